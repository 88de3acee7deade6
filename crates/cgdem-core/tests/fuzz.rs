//! Generated bad input for the core's parsers: the scene TOML, STL (ASCII and binary) and
//! LAMMPS data files (`read_data`).
//! No input may panic; every error names the file and the field or line (or triangle).
//! `cargo test` runs a few cases (64 per parser); `scripts/fuzz.sh` sets PROPTEST_CASES.

use std::path::Path;
use std::sync::atomic::AtomicU64;

use cgdem_core::geometry::stl::{stl_from_bytes, stl_unchecked_from_bytes};
use cgdem_core::scene::{given_particles_from_data, Scene};
use proptest::prelude::*;

#[path = "../../../tests/support/fuzz_cases.rs"]
mod fuzz_cases;
use fuzz_cases::{config, counted};

const SCENE: &str = include_str!("../../../tests/data/tiny_hertz_collapse.toml");
const SCENE_FILE: &str = "fuzz/scene.toml";
const STL_FILE: &str = "fuzz/body.stl";

/// A scene error names the file, and a field (`field \`...\``) or a line (TOML syntax).
fn check_scene(text: &str) {
    if let Err(e) = Scene::parse(text, Path::new(SCENE_FILE)) {
        let m = e.to_string();
        assert!(m.starts_with(SCENE_FILE), "no file in: {m}");
        assert!(
            m.contains("field `") || m.contains("line "),
            "neither field nor line in: {m}"
        );
    }
}

/// Values that break fields: wrong types, non-finite, huge, tiny, negative, empty.
fn bad_value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("0".to_string()),
        Just("-1".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e308".to_string()),
        Just("1e-320".to_string()),
        Just("18446744073709551615".to_string()),
        Just("-9223372036854775808".to_string()),
        Just("1e10".to_string()),
        Just("\"\"".to_string()),
        Just("\"x\"".to_string()),
        Just("[]".to_string()),
        Just("[1.0]".to_string()),
        Just("[nan, 0.0, 0.0]".to_string()),
        Just("true".to_string()),
        Just("{}".to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        any::<i64>().prop_map(|v| v.to_string()),
        "[a-z_]{0,8}".prop_map(|s| format!("\"{s}\"")),
    ]
}

/// The tiny collapse scene with one value replaced, lines dropped or duplicated, or cut.
fn mutated_scene() -> impl Strategy<Value = String> {
    let lines: Vec<String> = SCENE.lines().map(str::to_string).collect();
    let n = lines.len();
    prop_oneof![
        (0..n, bad_value()).prop_map({
            let lines = lines.clone();
            move |(k, v)| {
                let mut l = lines.clone();
                if let Some(eq) = l[k].find('=') {
                    l[k] = format!("{}= {v}", &l[k][..eq]);
                }
                l.join("\n")
            }
        }),
        (0..n, 0..n).prop_map({
            let lines = lines.clone();
            move |(a, b)| {
                let mut l = lines.clone();
                l.remove(a.min(n - 1));
                if b < l.len() {
                    let dup = l[b].clone();
                    l.insert(b, dup);
                }
                l.join("\n")
            }
        }),
        (0..SCENE.len()).prop_map(|cut| {
            let mut c = cut;
            while !SCENE.is_char_boundary(c) {
                c -= 1;
            }
            SCENE[..c].to_string()
        }),
        (0..n, "[a-z_.]{1,12}", bad_value()).prop_map({
            let lines = lines.clone();
            move |(k, key, v)| {
                let mut l = lines.clone();
                l.insert(k, format!("{key} = {v}"));
                l.join("\n")
            }
        }),
    ]
}

/// A data file for the tiny collapse's species and box: two atoms, velocities and spins.
const DATA: &str = "LAMMPS data file (fuzz base)

2 atoms
2 atom types

0.0 0.15 xlo xhi
0.0 0.04 ylo yhi
0.0 0.12 zlo zhi

Atoms # sphere

1 1 1.0e-2 2500.0 0.02 0.02 0.02
2 1 1.0e-2 2500.0 0.05 0.02 0.02 0 0 0

Velocities

1 0.0 0.0 -1.0 0.0 30.0 0.0
2 0.5 0.0 0.0 0.0 0.0 0.0
";
const DATA_FILE: &str = "fuzz/start.data";

/// A data-file error names the scene, the data file and a field (with the line where one is
/// to blame).
fn check_data(text: &str) {
    static SPECIES: std::sync::OnceLock<Scene> = std::sync::OnceLock::new();
    let scene = SPECIES.get_or_init(|| Scene::parse(SCENE, Path::new(SCENE_FILE)).unwrap());
    for rotates in [true, false] {
        if let Err(e) = given_particles_from_data(
            text,
            Path::new(DATA_FILE),
            Path::new(SCENE_FILE),
            &scene.species,
            &scene.domain,
            rotates,
        ) {
            let m = e.to_string();
            assert!(
                m.starts_with(SCENE_FILE) && m.contains(DATA_FILE),
                "no files in: {m}"
            );
            assert!(m.contains("field `"), "no field in: {m}");
        }
    }
}

/// The base data file with a token replaced by a bad one, lines dropped or duplicated, or cut.
fn mutated_data() -> impl Strategy<Value = String> {
    let lines: Vec<String> = DATA.lines().map(str::to_string).collect();
    let n = lines.len();
    let token = prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("3".to_string()),
        Just("1e308".to_string()),
        Just("18446744073709551616".to_string()),
        Just("# sphere".to_string()),
        Just("Atoms".to_string()),
        Just("".to_string()),
        any::<f64>().prop_map(|v| format!("{v:e}")),
        any::<i64>().prop_map(|v| v.to_string()),
        "[a-zA-Z#]{1,8}",
    ];
    prop_oneof![
        (0..n, 0..10usize, token).prop_map({
            let lines = lines.clone();
            move |(k, t, v)| {
                let mut l = lines.clone();
                let mut tokens: Vec<String> = l[k].split_whitespace().map(str::to_string).collect();
                if tokens.is_empty() {
                    tokens.push(v);
                } else {
                    let t = t % (tokens.len() + 1);
                    if t == tokens.len() {
                        tokens.push(v);
                    } else {
                        tokens[t] = v;
                    }
                }
                l[k] = tokens.join(" ");
                l.join("\n")
            }
        }),
        (0..n, 0..n).prop_map({
            let lines = lines.clone();
            move |(a, b)| {
                let mut l = lines.clone();
                l.remove(a.min(n - 1));
                if b < l.len() {
                    let dup = l[b].clone();
                    l.insert(b, dup);
                }
                l.join("\n")
            }
        }),
        (0..DATA.len()).prop_map(|cut| DATA[..cut].to_string()),
    ]
}

static DATA_ANY: AtomicU64 = AtomicU64::new(0);
static DATA_MUTATED: AtomicU64 = AtomicU64::new(0);
static SCENE_ANY: AtomicU64 = AtomicU64::new(0);
static SCENE_MUTATED: AtomicU64 = AtomicU64::new(0);
static STL_BYTES: AtomicU64 = AtomicU64::new(0);
static STL_BINARY: AtomicU64 = AtomicU64::new(0);
static STL_ASCII: AtomicU64 = AtomicU64::new(0);

/// A binary STL: `count` in the header (maybe not the real one), triangles with any f32
/// (NaN, infinities, huge), then cut at `keep` bytes.
fn binary_stl() -> impl Strategy<Value = Vec<u8>> {
    let coordinate = prop_oneof![
        4 => -10.0f32..10.0,
        1 => Just(f32::NAN),
        1 => Just(f32::INFINITY),
        1 => Just(f32::MAX),
        1 => any::<f32>(),
    ];
    (
        proptest::collection::vec(proptest::array::uniform12(coordinate), 0..12),
        prop_oneof![Just(None), any::<u32>().prop_map(Some)],
        any::<bool>(),
        any::<u16>(),
    )
        .prop_map(|(triangles, count, cut, keep)| {
            let mut b = vec![0u8; 80];
            if cut && keep % 3 == 0 {
                b[..5].copy_from_slice(b"solid");
            }
            let n = count.unwrap_or(triangles.len() as u32);
            b.extend_from_slice(&n.to_le_bytes());
            for t in &triangles {
                b.extend_from_slice(&[0u8; 12]); // normal
                for v in t {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                b.extend_from_slice(&[0u8; 2]);
            }
            if cut {
                b.truncate(keep as usize % (b.len() + 1));
            }
            b
        })
}

/// An ASCII STL with numbers that may be garbage, non-finite or out of range, keywords that
/// may be missing, cut anywhere.
fn ascii_stl() -> impl Strategy<Value = Vec<u8>> {
    let number = prop_oneof![
        6 => (-10.0f64..10.0).prop_map(|v| format!("{v}")),
        1 => Just("nan".to_string()),
        1 => Just("inf".to_string()),
        1 => Just("1e400".to_string()),
        1 => Just("-1e39".to_string()),
        1 => "[a-z0-9.+-]{0,6}",
    ];
    let keyword = prop_oneof![
        8 => Just(None),
        1 => Just(Some("")),
        1 => Just(Some("facet")),
        1 => Just(Some("endloop endloop")),
    ];
    (
        proptest::collection::vec((proptest::collection::vec(number, 9..13), keyword), 0..6),
        any::<bool>(),
        any::<u16>(),
    )
        .prop_map(|(facets, cut, keep)| {
            let mut s = String::from("solid fuzz\n");
            for (numbers, replace) in facets {
                let mut v = numbers.into_iter();
                let mut next = || v.next().unwrap_or_default();
                let mut facet = "facet normal 0 0 1\n outer loop\n".to_string();
                for _ in 0..3 {
                    facet += &format!("  vertex {} {} {}\n", next(), next(), next());
                }
                facet += " endloop\nendfacet\n";
                if let Some(r) = replace {
                    facet = facet.replacen("outer loop", r, 1);
                }
                s += &facet;
            }
            s += "endsolid fuzz\n";
            let mut b = s.into_bytes();
            if cut {
                b.truncate(keep as usize % (b.len() + 1));
            }
            b
        })
}

/// An STL error names the file; one from the reader proper says which triangle or what size.
fn check_stl(bytes: &[u8]) {
    let path = Path::new(STL_FILE);
    for result in [
        stl_from_bytes(bytes, path).map(|_| ()),
        stl_unchecked_from_bytes(bytes, path).map(|_| ()),
    ] {
        if let Err(e) = result {
            let m = e.to_string();
            assert!(m.contains(STL_FILE), "no file in: {m}");
        }
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn scene_parser_takes_any_text(text in any::<String>()) {
        check_scene(&text);
        counted(&SCENE_ANY, "scene (any text)");
    }

    #[test]
    fn scene_parser_takes_mutated_scenes(text in mutated_scene()) {
        check_scene(&text);
        counted(&SCENE_MUTATED, "scene (mutated tiny_hertz_collapse)");
    }

    #[test]
    fn data_file_reader_takes_any_text(text in any::<String>()) {
        check_data(&text);
        counted(&DATA_ANY, "read_data (any text)");
    }

    #[test]
    fn data_file_reader_takes_mutated_files(text in mutated_data()) {
        check_data(&text);
        counted(&DATA_MUTATED, "read_data (mutated: tokens, lines, cuts)");
    }

    #[test]
    fn stl_reader_takes_any_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        check_stl(&bytes);
        counted(&STL_BYTES, "stl (any bytes)");
    }

    #[test]
    fn stl_reader_takes_bad_binary_files(bytes in binary_stl()) {
        check_stl(&bytes);
        counted(&STL_BINARY, "stl (binary: counts, NaN, cuts)");
    }

    #[test]
    fn stl_reader_takes_bad_ascii_files(bytes in ascii_stl()) {
        check_stl(&bytes);
        counted(&STL_ASCII, "stl (ascii: numbers, keywords, cuts)");
    }
}

/// The fuzzers' base data file is read (so the mutations start from a good file).
#[test]
fn the_fuzz_base_data_file_is_good() {
    check_data(DATA);
    let scene = Scene::parse(SCENE, Path::new(SCENE_FILE)).unwrap();
    let p = given_particles_from_data(
        DATA,
        Path::new(DATA_FILE),
        Path::new(SCENE_FILE),
        &scene.species,
        &scene.domain,
        true,
    )
    .unwrap();
    assert_eq!(p.len(), 2);
}

/// A header that claims 2^32 - 1 triangles in an 84-byte file: refused by size, at once.
#[test]
fn binary_stl_with_a_huge_triangle_count_is_refused_without_allocating() {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&u32::MAX.to_le_bytes());
    let e = stl_from_bytes(&b, Path::new(STL_FILE))
        .unwrap_err()
        .to_string();
    assert!(e.contains(STL_FILE) && e.contains("triangle count"), "{e}");
}
