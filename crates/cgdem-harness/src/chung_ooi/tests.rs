use std::path::Path;

use crate::suite::Suite;

#[test]
fn a_law_needs_a_unique_name_and_valid_overrides() {
    let entry = |law: &str, set: &str| {
        format!("name = \"t\"\n[[chung_ooi]]\nlaw = \"{law}\"\nset = [{set}]\n")
    };
    let ok = Suite::parse(
        &entry("elastic", "\"contact.limit_force=true\""),
        Path::new("s.toml"),
    )
    .unwrap();
    assert_eq!(ok.chung_ooi[0].name, "elastic");
    for (text, field) in [
        (entry("a b", ""), "chung_ooi[0].law"),
        (entry("x", "\"limit_force\""), "chung_ooi[0].set"),
        (
            format!("{}[[chung_ooi]]\nlaw = \"x\"\n", entry("x", "")),
            "chung_ooi[1].law",
        ),
    ] {
        let e = Suite::parse(&text, Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains(field), "{e}");
    }
}
