//! `docs/cli.md`, the command-line reference, is generated from the clap definitions (each
//! command's `--help`), so it cannot drift from them: this test fails when it is stale, and
//! `CGDEM_BLESS=1` rewrites it. Its last section, the exit statuses, is written by hand and
//! kept as it is; it must name every command. The help texts speak the user's words: no
//! nickname of a source paper or of its rule, no "main job", no issue numbers.

use std::path::Path;
use std::process::Command;

/// The long help of `cgdem <path...> --help`.
fn help(path: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_cgdem"))
        .args(path)
        .arg("--help")
        .env("COLUMNS", "100")
        .output()
        .expect("cgdem runs");
    assert!(out.status.success(), "cgdem {path:?} --help failed");
    String::from_utf8(out.stdout).expect("help is UTF-8")
}

/// The subcommands a help text lists under `Commands:` (but `help`).
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| l.trim() != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// One section per command, depth first, in the order `--help` lists them.
fn sections(path: &mut Vec<String>, out: &mut String) {
    let args: Vec<&str> = path.iter().map(String::as_str).collect();
    let text = help(&args);
    let title = std::iter::once("cgdem")
        .chain(args.iter().copied())
        .collect::<Vec<_>>()
        .join(" ");
    let level = "#".repeat(2 + path.len().min(1));
    // The version changes with every release and with the `mpi` feature: not written.
    let text = text.replace(concat!(" ", env!("CARGO_PKG_VERSION")), "");
    out.push_str(&format!(
        "{level} `{title}`\n\n```text\n{}\n```\n\n",
        text.trim_end()
    ));
    for sub in subcommands(&text) {
        path.push(sub);
        sections(path, out);
        path.pop();
    }
}

fn reference() -> String {
    let mut out = String::from(
        "# Command-line reference\n\n\
         Generated from the command's own `--help` by `tests/integration/cli_reference.rs`; \
         do not edit by hand. After changing an argument, rewrite it with\n\
         `CGDEM_BLESS=1 cargo test --release --test integration cli_reference`.\n\n",
    );
    sections(&mut Vec::new(), &mut out);
    out.truncate(out.trim_end().len());
    out.push('\n');
    out
}

/// The hand-written section of docs/cli.md that follows the generated reference.
const EXIT_STATUS: &str = "\n## Exit status\n";

#[test]
fn cli_reference_in_docs_is_the_commands_own_help() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/cli.md");
    let fresh = reference();
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    let (generated, by_hand) = match stored.find(EXIT_STATUS) {
        Some(at) => stored.split_at(at + 1),
        None => (stored.as_str(), ""),
    };
    if std::env::var_os("CGDEM_BLESS").is_some_and(|v| v == "1") {
        std::fs::write(&path, format!("{fresh}\n{by_hand}")).expect("docs/cli.md is writable");
        return;
    }
    assert!(
        generated.trim_end() == fresh.trim_end(),
        "{} is stale (an argument or its help changed): rewrite it with \
         `CGDEM_BLESS=1 cargo test --release --test integration cli_reference`",
        path.display()
    );
}

/// Every command, depth first (`run`, `reference lammps`, ...), with its help text.
fn every_help(path: &mut Vec<String>, out: &mut Vec<(String, String)>) {
    let args: Vec<&str> = path.iter().map(String::as_str).collect();
    let text = help(&args);
    out.push((args.join(" "), text.clone()));
    for sub in subcommands(&text) {
        path.push(sub);
        every_help(path, out);
        path.pop();
    }
}

/// The internal words of `text` (lower case): a source paper or its rule or model called
/// "the seed", "the main job", an issue number.
fn internal_words(text: &str) -> Vec<String> {
    let lower = text.to_lowercase();
    let mut found: Vec<String> = [
        "seed paper",
        "seed rule",
        "seed model",
        "seed's",
        "main job",
    ]
    .iter()
    .filter(|w| lower.contains(*w))
    .map(|w| w.to_string())
    .collect();
    found.extend(lower.match_indices("issue ").filter_map(|(at, _)| {
        let next = lower[at + 6..].chars().next()?;
        next.is_ascii_digit()
            .then(|| lower[at..(at + 8).min(lower.len())].to_string())
    }));
    found
}

#[test]
fn no_help_text_uses_internal_words() {
    assert_eq!(
        internal_words("the Seed Rule, issue 52"),
        ["seed rule", "issue 52"]
    );
    assert!(internal_words("--seed: insertion seed; an issue with 2 seeds").is_empty());
    let mut helps = Vec::new();
    every_help(&mut Vec::new(), &mut helps);
    assert!(helps.len() > 10, "{} commands", helps.len());
    for (command, text) in helps {
        let words = internal_words(&text);
        assert!(words.is_empty(), "cgdem {command} --help: {words:?}");
    }
}

#[test]
fn the_exit_status_table_names_every_command() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/cli.md");
    let stored = std::fs::read_to_string(&path).unwrap();
    let table = &stored[stored
        .find(EXIT_STATUS)
        .expect("docs/cli.md has its exit statuses")..];
    for command in subcommands(&help(&[])) {
        assert!(
            table.contains(&format!("| `{command}`")),
            "docs/cli.md, \"Exit status\": no row for `cgdem {command}`"
        );
    }
}
