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
/// The same with two materials: species' own, `[[contact.pair]]`, `[[wall_material]]`,
/// `[[wall_contact.pair]]` and a wall naming its material.
const MATERIALS_SCENE: &str = include_str!("../../../tests/data/tiny_two_material_collapse.toml");
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
    mutated(SCENE)
}

/// `base` with one value replaced, lines dropped or duplicated, a line inserted, or cut.
fn mutated(base: &'static str) -> impl Strategy<Value = String> {
    let lines: Vec<String> = base.lines().map(str::to_string).collect();
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
        (0..base.len()).prop_map(move |cut| {
            let mut c = cut;
            while !base.is_char_boundary(c) {
                c -= 1;
            }
            base[..c].to_string()
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

/// A valid Hertz scene with generated material tables: 1-3 species, each maybe with its own
/// Young's modulus and Poisson's ratio; a subset of the species pairs (each once, in either
/// order) with some coefficients; 0-2 wall materials named by the walls; a subset of the
/// (species, wall material) pairs. Returned with what was given, to check the resolution.
#[derive(Clone, Debug)]
struct Tables {
    species: Vec<(Option<f64>, Option<f64>)>,
    pairs: Vec<GivenPair>,
    wall_materials: Vec<(f64, f64)>,
    wall_pairs: Vec<GivenWallPair>,
    wall_material: Option<usize>,
}

/// (a, b, restitution, friction, rolling friction)
type GivenPair = (usize, usize, Option<f64>, Option<f64>, Option<f64>);
/// (species, material or None for the default, restitution, friction)
type GivenWallPair = (usize, Option<usize>, Option<f64>, Option<f64>);

fn tables() -> impl Strategy<Value = Tables> {
    let modulus = prop_oneof![Just(None), (5e6f64..1e9).prop_map(Some)];
    let poisson = prop_oneof![Just(None), (0.0f64..0.49).prop_map(Some)];
    let coefficient = |lo: f64, hi: f64| prop_oneof![Just(None), (lo..hi).prop_map(Some)];
    (1usize..=3, 0usize..=2).prop_flat_map(move |(n, n_wall)| {
        let unordered: Vec<(usize, usize)> =
            (0..n).flat_map(|a| (a..n).map(move |b| (a, b))).collect();
        let wall_keys: Vec<(usize, Option<usize>)> = (0..n)
            .flat_map(|a| std::iter::once((a, None)).chain((0..n_wall).map(move |k| (a, Some(k)))))
            .collect();
        (
            proptest::collection::vec((modulus.clone(), poisson.clone()), n),
            proptest::sample::subsequence(unordered.clone(), 0..=unordered.len()),
            proptest::collection::vec(
                (
                    any::<bool>(),
                    coefficient(0.05, 1.0),
                    coefficient(0.0, 1.0),
                    coefficient(0.0, 0.5),
                ),
                unordered.len(),
            ),
            proptest::collection::vec((5e6f64..1e11, 0.0f64..0.49), n_wall),
            proptest::sample::subsequence(wall_keys.clone(), 0..=wall_keys.len()),
            proptest::collection::vec(
                (coefficient(0.05, 1.0), coefficient(0.0, 1.0)),
                wall_keys.len(),
            ),
            prop_oneof![Just(None), (0..n_wall.max(1)).prop_map(Some)],
        )
            .prop_map(
                move |(species, pairs, values, wall_materials, wall_keys, wall_values, wall)| {
                    let pairs = pairs
                        .into_iter()
                        .zip(values)
                        .map(|((a, b), (swap, e, mu, mu_r))| {
                            let (a, b) = if swap { (b, a) } else { (a, b) };
                            // At least one coefficient per pair.
                            (a, b, e, mu.or(Some(0.25)), mu_r)
                        })
                        .collect();
                    let wall_pairs = wall_keys
                        .into_iter()
                        .zip(wall_values)
                        .map(|((a, k), (e, mu))| (a, k, e.or(Some(0.5)), mu))
                        .collect();
                    Tables {
                        species,
                        pairs,
                        wall_material: wall.filter(|&k| k < wall_materials.len()),
                        wall_materials,
                        wall_pairs,
                    }
                },
            )
    })
}

/// The scene text of `t`: tiny_hertz_collapse's box, law and stages.
fn tables_scene(t: &Tables) -> String {
    let mut s = String::from(
        "name = \"tables\"\n[domain]\nlo = [0.0, 0.0, 0.0]\nhi = [0.15, 0.04, 0.12]\n",
    );
    let opt = |name: &str, v: Option<f64>| v.map_or(String::new(), |v| format!("{name} = {v:e}\n"));
    for (k, (e, nu)) in t.species.iter().enumerate() {
        s += &format!("[[species]]\nname = \"s{k}\"\ndiameter = 1.0e-2\ndensity = 2500.0\n");
        s += &opt("youngs_modulus", *e);
        s += &opt("poisson_ratio", *nu);
    }
    s += "[contact]\nmodel = \"hertz\"\nyoungs_modulus = 5.0e6\npoisson_ratio = 0.3\nrestitution = 0.5\nfriction = 0.5\nrolling_friction = 0.1\nrolling = \"epsd2\"\n";
    for (a, b, e, mu, mu_r) in &t.pairs {
        s += &format!("[[contact.pair]]\nspecies = [\"s{a}\", \"s{b}\"]\n");
        s += &opt("restitution", *e);
        s += &opt("friction", *mu);
        s += &opt("rolling_friction", *mu_r);
    }
    for (k, (e, nu)) in t.wall_materials.iter().enumerate() {
        s += &format!(
            "[[wall_material]]\nname = \"w{k}\"\nyoungs_modulus = {e:e}\npoisson_ratio = {nu:e}\n"
        );
    }
    s += "[wall_contact]\nrestitution = 0.7\nfriction = 0.45\n";
    for (a, k, e, mu) in &t.wall_pairs {
        s += &format!("[[wall_contact.pair]]\nspecies = \"s{a}\"\n");
        if let Some(k) = k {
            s += &format!("material = \"w{k}\"\n");
        }
        s += &opt("restitution", *e);
        s += &opt("friction", *mu);
    }
    s += "[[wall]]\nname = \"floor\"\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 0.0, 1.0]\n";
    if let Some(k) = t.wall_material {
        s += &format!("material = \"w{k}\"\n");
    }
    s += "[time]\ndt_fraction = 0.05\n[[stage]]\nname = \"s\"\nduration = 0.1\n";
    s
}

/// A generated valid scene parses, and every pair resolves to its own value, else the default.
fn check_tables(t: &Tables) {
    use cgdem_core::scene::ContactTables;
    let scene = Scene::parse(&tables_scene(t), Path::new(SCENE_FILE))
        .unwrap_or_else(|e| panic!("{e}\n{}", tables_scene(t)));
    let r = ContactTables::of(&scene).unwrap();
    let n = t.species.len();
    for (k, (e, nu)) in t.species.iter().enumerate() {
        assert_eq!(r.species[k].youngs_modulus, e.unwrap_or(5e6));
        assert_eq!(r.species[k].poisson_ratio, nu.unwrap_or(0.3));
    }
    for a in 0..n {
        for b in 0..n {
            let given = t
                .pairs
                .iter()
                .find(|p| (p.0, p.1) == (a, b) || (p.0, p.1) == (b, a));
            let p = r.pair(a, b);
            assert_eq!(p, r.pair(b, a));
            assert_eq!(r.y_eff(a, b), r.y_eff(b, a));
            assert_eq!(p.restitution, given.and_then(|g| g.2).unwrap_or(0.5));
            assert_eq!(p.friction, given.and_then(|g| g.3).unwrap_or(0.5));
            assert_eq!(p.rolling_friction, given.and_then(|g| g.4).unwrap_or(0.1));
        }
        for k in 0..=t.wall_materials.len() {
            let given = t
                .wall_pairs
                .iter()
                .find(|p| p.0 == a && p.1.map_or(0, |m| m + 1) == k);
            let p = r.wall_pair(a, k);
            assert_eq!(p.restitution, given.and_then(|g| g.2).unwrap_or(0.7));
            assert_eq!(p.friction, given.and_then(|g| g.3).unwrap_or(0.45));
        }
    }
    assert_eq!(
        scene.walls[0].material,
        t.wall_material.map_or(0, |k| k + 1)
    );
}

static TABLES_VALID: AtomicU64 = AtomicU64::new(0);
static TABLES_MUTATED: AtomicU64 = AtomicU64::new(0);

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
    fn generated_material_tables_resolve_each_pair_to_its_own_value(t in tables()) {
        check_tables(&t);
        counted(&TABLES_VALID, "scene material tables (generated, valid)");
    }

    #[test]
    fn scene_parser_takes_mutated_material_scenes(text in mutated(MATERIALS_SCENE)) {
        check_scene(&text);
        counted(&TABLES_MUTATED, "scene (mutated tiny_two_material_collapse)");
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

/// The materials scene the mutations start from is good, and has materials.
#[test]
fn the_fuzz_base_materials_scene_is_good() {
    let scene = Scene::parse(MATERIALS_SCENE, Path::new(SCENE_FILE)).unwrap();
    let t = cgdem_core::scene::ContactTables::of(&scene).unwrap();
    assert!(!t.is_uniform() && t.n_wall_materials() == 2);
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
