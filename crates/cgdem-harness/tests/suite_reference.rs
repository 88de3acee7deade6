//! docs/suite-files.md, the suite-file reference, is checked against the parser as the
//! command-line reference is against `--help`: every key the parser accepts in each table
//! has its row there, and the page's complete example, which uses every documented key,
//! parses. The parser's keys are read from its own refusal of an unknown key (serde's
//! `deny_unknown_fields` lists the keys it expected), so a key added to the parser without
//! its row, or a row whose key the parser refuses, fails this test.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use cgdem_harness::suite::Suite;

fn page() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/suite-files.md"))
        .expect("docs/suite-files.md is readable")
}

/// The keys each table of the page documents, by table (`""` for the suite's own keys,
/// `case`, `case.known_difference`, ...): the first column of the table rows under the
/// table's heading, and the tables a parent holds, as keys of their parent.
fn documented(page: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut table: Option<String> = None;
    for line in page.lines() {
        if let Some(heading) = line
            .strip_prefix("## ")
            .or_else(|| line.strip_prefix("### "))
        {
            table = if heading == "The suite" {
                Some(String::new())
            } else if heading.starts_with("`[") {
                let name = heading.trim_matches(|c| "`[]".contains(c)).to_string();
                let (parent, key) = name.rsplit_once('.').unwrap_or(("", &name));
                out.entry(parent.into()).or_default().insert(key.into());
                Some(name)
            } else {
                None
            };
            continue;
        }
        let (Some(t), Some(row)) = (&table, line.strip_prefix("| `")) else {
            continue;
        };
        let key = row.split('`').next().unwrap();
        out.entry(t.clone()).or_default().insert(key.to_string());
    }
    out
}

/// The keys the parser accepts in a table: a suite with an unknown key `zz_unknown` in
/// that table (`before` the key, `after` it), refused, names what it expected.
fn accepted(before: &str, after: &str) -> BTreeSet<String> {
    let text = format!("{before}zz_unknown = 1\n{after}");
    let e = Suite::parse(&text, Path::new("probe.toml"))
        .expect_err("an unknown key is refused")
        .to_string();
    let expected = e
        .split_once("expected")
        .unwrap_or_else(|| panic!("no list of expected keys in: {e}"))
        .1;
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

const CASE: &str =
    "name = \"t\"\n[[case]]\nfile = \"c.toml\"\ncodes = [\"cgdem\"]\nlambdas = [1]\nseeds = [1]\n";
const ACCURACY: &str =
    "name = \"t\"\n[[accuracy]]\nfile = \"c.toml\"\nvariant = \"v\"\nreference = { lambda = 1 }\n";

#[test]
fn every_key_the_parser_accepts_is_documented() {
    let docs = documented(&page());
    let probes: [(&str, String, &str); 8] = [
        (
            "",
            "name = \"t\"\n".into(),
            "[[stability]]\nfile = \"c.toml\"\n",
        ),
        ("case", CASE.into(), ""),
        (
            "case.known_difference",
            format!("{CASE}[[case.known_difference]]\n"),
            "",
        ),
        ("case.discharge", format!("{CASE}[case.discharge]\n"), ""),
        ("accuracy", ACCURACY.into(), ""),
        (
            "accuracy.series",
            format!("{ACCURACY}[[accuracy.series]]\n"),
            "",
        ),
        // Documented once, under `[case.discharge]`, as the same table.
        (
            "case.discharge",
            format!("{ACCURACY}[accuracy.discharge]\n"),
            "",
        ),
        (
            "stability",
            "name = \"t\"\n[[stability]]\nfile = \"c.toml\"\n".into(),
            "",
        ),
    ];
    for (table, before, after) in probes {
        let parser = accepted(&before, after);
        assert!(parser.len() >= 2, "{table}: {parser:?}");
        let page = docs.get(table).cloned().unwrap_or_default();
        let missing: Vec<&String> = parser.difference(&page).collect();
        assert!(
            missing.is_empty(),
            "docs/suite-files.md, table `{table}`: no row for {missing:?}"
        );
        let unknown: Vec<&String> = page.difference(&parser).collect();
        assert!(
            unknown.is_empty(),
            "docs/suite-files.md, table `{table}`: rows the parser refuses: {unknown:?}"
        );
    }
}

#[test]
fn the_complete_example_uses_every_documented_key_and_parses() {
    let page = page();
    let example = page
        .split_once("## Example: every key")
        .and_then(|(_, rest)| rest.split_once("```toml\n"))
        .and_then(|(_, rest)| rest.split_once("```"))
        .expect("docs/suite-files.md has its complete example")
        .0;
    for (table, keys) in documented(&page) {
        for key in keys {
            let used = example.lines().any(|l| {
                l.starts_with(&format!("{key} ="))
                    || l.contains(&format!("[{key}]"))
                    || l.contains(&format!(".{key}]"))
            });
            assert!(
                used,
                "the complete example does not use `{key}` of `{table}`"
            );
        }
    }
    // Its paths are relative to the suite file: the evidence must exist beside it.
    let dir = std::env::temp_dir().join(format!("cgdem-suite-ref-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("notes")).unwrap();
    std::fs::write(dir.join("notes/hopper.md"), "why they differ").unwrap();
    // Resolved against the working directory by older parsers: the same directory here.
    std::env::set_current_dir(&dir).unwrap();
    let suite = Suite::parse(example, &dir.join("hopper-suite.toml"));
    let _ = std::fs::remove_dir_all(&dir);
    let suite = suite.unwrap_or_else(|e| panic!("the complete example: {e}"));
    assert_eq!(
        (
            suite.cases.len(),
            suite.accuracy.len(),
            suite.stability.len()
        ),
        (2, 2, 1)
    );
}
