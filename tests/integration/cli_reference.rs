//! `docs/cli.md`, the command-line reference, is generated from the clap definitions (each
//! command's `--help`), so it cannot drift from them: this test fails when it is stale, and
//! `CGDEM_BLESS=1` rewrites it.

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

#[test]
fn cli_reference_in_docs_is_the_commands_own_help() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/cli.md");
    let fresh = reference();
    if std::env::var_os("CGDEM_BLESS").is_some_and(|v| v == "1") {
        std::fs::write(&path, &fresh).expect("docs/cli.md is writable");
        return;
    }
    let stored = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        stored == fresh,
        "{} is stale (an argument or its help changed): rewrite it with \
         `CGDEM_BLESS=1 cargo test --release --test integration cli_reference`",
        path.display()
    );
}
