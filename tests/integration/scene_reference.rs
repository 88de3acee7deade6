//! `docs/scene-files.md` lists every key the scene parser accepts, with its unit, default and
//! allowed range: this test fails when the parser (`crates/cgdem-core/src/scene/raw.rs`, its
//! serde structs) accepts a key the chapter does not list, or the chapter lists one the
//! parser refuses. The chapter's `##` sections are the tables (`[domain]`, `[[species]]`,
//! "Top level" for the keys outside any table); each key is the first cell of a row, and a
//! nested table's keys are written `refill.interval` in its parent's section or get a section
//! of their own (`[insert.refill]`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A field of a raw struct: its key in the file and the raw struct it holds, if any.
struct Field {
    key: String,
    table: Option<String>,
}

/// `pub struct RawX { ... }` blocks of raw.rs: each struct's fields, keys renamed as serde
/// renames them.
fn raw_structs(source: &str) -> BTreeMap<String, Vec<Field>> {
    let mut structs = BTreeMap::new();
    let mut current: Option<(String, Vec<Field>)> = None;
    let mut rename: Option<String> = None;
    for line in source.lines().map(str::trim) {
        if let Some(rest) = line.strip_prefix("pub struct ") {
            let name = rest.trim_end_matches('{').trim().to_string();
            current = Some((name, Vec::new()));
            continue;
        }
        let Some((_, fields)) = current.as_mut() else {
            continue;
        };
        if line == "}" {
            let (name, fields) = current.take().expect("inside a struct");
            structs.insert(name, fields);
            continue;
        }
        if line.starts_with("#[serde(") {
            // Attributes this reading does not model would make it wrong: stop and say so.
            for unknown in ["flatten", "alias", "untagged", "rename_all"] {
                assert!(
                    !line.contains(unknown),
                    "raw.rs uses `{unknown}`; teach tests/integration/scene_reference.rs to read it"
                );
            }
            rename = line
                .split("rename = \"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .map(str::to_string);
            continue;
        }
        if let Some(rest) = line.strip_prefix("pub ") {
            let (name, ty) = rest.split_once(':').expect("a field is `pub name: Type,`");
            let table = ty
                .split(|c: char| !c.is_alphanumeric() && c != '_')
                .find(|word| word.starts_with("Raw"))
                .map(str::to_string);
            fields.push(Field {
                key: rename.take().unwrap_or_else(|| name.trim().to_string()),
                table,
            });
        }
    }
    structs
}

/// Every key the parser accepts, as `table.key` (`key` at the top level, `insert.refill.stage`
/// for a nested table's).
fn parser_keys(structs: &BTreeMap<String, Vec<Field>>, name: &str, path: &str) -> Vec<String> {
    let fields = structs
        .get(name)
        .unwrap_or_else(|| panic!("raw.rs has no struct {name}"));
    let mut keys = Vec::new();
    for field in fields {
        let full = if path.is_empty() {
            field.key.clone()
        } else {
            format!("{path}.{}", field.key)
        };
        match &field.table {
            Some(table) => keys.extend(parser_keys(structs, table, &full)),
            None => keys.push(full),
        }
    }
    keys
}

/// Every key the chapter lists, as `table.key`.
fn chapter_keys(text: &str) -> Vec<String> {
    let mut keys = Vec::new();
    // None: a section that is no table (its rows would be an error).
    let mut section: Option<String> = None;
    for line in text.lines() {
        if let Some(heading) = line.strip_prefix("## ") {
            section = if heading.trim() == "Top level" {
                Some(String::new())
            } else {
                heading
                    .split('`')
                    .nth(1)
                    .filter(|t| t.starts_with('['))
                    .map(|t| t.trim_matches(|c| c == '[' || c == ']').to_string())
            };
            continue;
        }
        let Some(first_cell) = line.strip_prefix("| ").and_then(|l| l.split(" |").next()) else {
            continue;
        };
        if !first_cell.starts_with('`') {
            continue; // a header row or a separator
        }
        let table = section.as_ref().unwrap_or_else(|| {
            panic!("docs/scene-files.md: a key row outside a table's section: {line}")
        });
        for key in first_cell.split('`').skip(1).step_by(2) {
            keys.push(if table.is_empty() {
                key.to_string()
            } else {
                format!("{table}.{key}")
            });
        }
    }
    keys
}

#[test]
fn every_scene_key_the_parser_accepts_is_in_the_scene_file_chapter() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let source = std::fs::read_to_string(root.join("crates/cgdem-core/src/scene/raw.rs"))
        .expect("raw.rs is readable");
    let chapter =
        std::fs::read_to_string(root.join("docs/scene-files.md")).expect("the chapter is readable");
    let parser: BTreeSet<String> = parser_keys(&raw_structs(&source), "RawScene", "")
        .into_iter()
        .collect();
    // The reading itself: a few keys of every kind must be found, or the test proves nothing.
    for known in [
        "name",
        "domain.lost",
        "species.frozen",
        "insert.refill.stage",
        "body.particles.species",
    ] {
        assert!(
            parser.contains(known),
            "raw.rs read wrongly: no `{known}` in {parser:?}"
        );
    }
    let documented: BTreeSet<String> = chapter_keys(&chapter).into_iter().collect();
    let missing: Vec<_> = parser.difference(&documented).collect();
    let unknown: Vec<_> = documented.difference(&parser).collect();
    assert!(
        missing.is_empty() && unknown.is_empty(),
        "docs/scene-files.md is stale: keys the parser accepts but the chapter does not list \
         (add a row with unit, default and allowed range, as the validator enforces them): \
         {missing:?}; keys the chapter lists but the parser refuses: {unknown:?}"
    );
}
