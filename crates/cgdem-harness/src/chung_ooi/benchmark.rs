//! The eight tests of Chung & Ooi (2011), "Benchmark tests for verifying discrete element
//! modelling codes at particle impact level", Granular Matter 13, 643-656: their inputs (the
//! paper's materials, speeds and spins, as Kratos DEM's public benchmark inputs give them),
//! what each measures, and the criteria it is judged by (Kratos DEM's
//! `DEM_benchmarks_class.py`: the points and tolerances it uses).

use cgdem_core::math::{Real, Vec3};

use super::collision::{Impact, Material, Outcome, Sphere};
use super::reference;

pub const GLASS: Material = Material {
    youngs_modulus: 4.8e10,
    poisson_ratio: 0.20,
    density: 2800.0,
};
pub const AL_ALLOY: Material = Material {
    youngs_modulus: 7.0e10,
    poisson_ratio: 0.33,
    density: 2700.0,
};
pub const AL_OXIDE: Material = Material {
    youngs_modulus: 3.8e11,
    poisson_ratio: 0.23,
    density: 4000.0,
};
pub const STEEL: Material = Material {
    youngs_modulus: 2.08e11,
    poisson_ratio: 0.30,
    density: 7850.0,
};
/// Test 8's large sphere (Kratos `benchmark8DEM.mdpa`): radius 0.5 m, 1000 times the Al.
/// alloy's density and Young's modulus, nearly a rigid sphere.
pub const HEAVY: Material = Material {
    youngs_modulus: 7.0e13,
    poisson_ratio: 0.33,
    density: 2.7e6,
};

/// One point of a curve: the test's abscissa, the measured value and, where one exists, the
/// closed form (Hertz theory, or rigid-body impact theory for a contact sliding throughout).
#[derive(Clone, Debug)]
pub struct Point {
    /// Kratos's point number (its `iteration`, 1-based).
    pub k: usize,
    pub x: Real,
    pub y: Real,
    pub closed_form: Option<Real>,
    /// Slides throughout (rigid-body theory, with a 20% margin on the sliding bound).
    pub sliding: bool,
}

/// A measured curve and what it is plotted against.
#[derive(Clone, Debug)]
pub struct Curve {
    pub stem: &'static str,
    pub title: &'static str,
    pub x_label: &'static str,
    pub y_label: &'static str,
    pub points: Vec<Point>,
    pub reference: Option<&'static reference::Digitized>,
}

/// One verdict: a value, the tolerance it must stay below, the points it uses and where the
/// rule and the reference values come from.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Criterion {
    pub name: String,
    pub value: Real,
    pub tolerance: Real,
    pub points: String,
    pub source: String,
    pub pass: bool,
}

impl Criterion {
    fn new(name: &str, value: Real, tolerance: Real, points: String, source: &str) -> Self {
        Criterion {
            name: name.into(),
            value,
            tolerance,
            points,
            source: source.into(),
            pass: value.is_finite() && value < tolerance,
        }
    }
}

#[derive(Clone, Debug)]
pub struct TestResult {
    pub number: u8,
    pub title: &'static str,
    pub inputs: String,
    pub curves: Vec<Curve>,
    pub criteria: Vec<Criterion>,
}

/// Runs one impact: `dt` a 200th of the Hertz contact time of the normal approach.
pub type Runner<'a> = dyn Fn(&Impact, Real) -> Result<Outcome, String> + 'a;

/// Hertz theory for an impact at relative normal speed `v`: (largest overlap, largest force,
/// contact time) with `E*` = `y`, `R*` = `r`, `m*` = `m`.
pub fn hertz(y: Real, r: Real, m: Real, v: Real) -> (Real, Real, Real) {
    let delta = (15.0 * m * v * v / (16.0 * y * r.sqrt())).powf(0.4);
    let force = 4.0 / 3.0 * y * r.sqrt() * delta.powf(1.5);
    // 2 integral_0^1 dx / sqrt(1 - x^(5/2)) = 2.9432: t_c = 2.9432 delta_max / v.
    (delta, force, 2.943_2 * delta / v)
}

fn e_star(a: Material, b: Option<Material>) -> Real {
    let part = |m: Material| (1.0 - m.poisson_ratio.powi(2)) / m.youngs_modulus;
    1.0 / (part(a) + b.map_or(0.0, part))
}

fn mass(m: Material, r: Real) -> Real {
    m.density * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3)
}

/// The time step of an impact: a 200th of its Hertz contact time.
pub fn time_step(impact: &Impact) -> Real {
    let a = &impact.sphere;
    let (r, m, v, y) = match &impact.partner {
        None => (
            a.radius,
            mass(a.material, a.radius),
            -a.velocity.z,
            e_star(a.material, None),
        ),
        Some(b) => {
            let (ma, mb) = (mass(a.material, a.radius), mass(b.material, b.radius));
            let n = (b.position - a.position).normalize();
            (
                a.radius * b.radius / (a.radius + b.radius),
                ma * mb / (ma + mb),
                (a.velocity - b.velocity).dot(n),
                e_star(a.material, Some(b.material)),
            )
        }
    };
    hertz(y, r, m, v).2 / 200.0
}

fn on_plane(material: Material, radius: Real, velocity: Vec3, omega: Vec3) -> Sphere {
    Sphere {
        material,
        radius,
        // A gap of a 100th of the radius: the contact starts within the first steps.
        position: Vec3::new(0.0, 0.0, 1.01 * radius),
        velocity,
        omega,
    }
}

/// Kratos's angles: `90/(n+1) k` degrees, k = 1..n, n = 17 (5 to 85 degrees).
fn angles() -> impl Iterator<Item = (usize, Real)> {
    (1..=17).map(|k| (k, (5.0 * k as Real).to_radians()))
}

fn rel(a: Real, b: Real) -> Real {
    (a - b).abs() / b.abs()
}

/// Kratos's error: `sum |measured - reference| / sum |reference|`, in percent.
fn kratos_error(measured: &[Real], reference: &[Real]) -> Real {
    let diff: Real = measured
        .iter()
        .zip(reference)
        .map(|(m, r)| (m - r).abs())
        .sum();
    100.0 * diff / reference.iter().map(|r| r.abs()).sum::<Real>()
}

/// The largest relative gap (percent) to the closed form over the points that have one
/// (`sliding_only`: over the points sliding throughout).
fn closed_form_gap(curve: &Curve, sliding_only: bool) -> (Real, String) {
    let used: Vec<&Point> = curve
        .points
        .iter()
        .filter(|p| p.closed_form.is_some() && (!sliding_only || p.sliding))
        .collect();
    let gap = used
        .iter()
        .map(|p| 100.0 * rel(p.y, p.closed_form.unwrap_or(Real::NAN)))
        .fold(0.0, Real::max);
    let ks: Vec<String> = used.iter().map(|p| p.k.to_string()).collect();
    let gap = if used.is_empty() { Real::NAN } else { gap };
    (gap, format!("k = {}", ks.join(", ")))
}

const HERTZ: &str = "Hertz theory (closed form); tolerance: Kratos DEM tests 1-2 (1%)";
const RIGID: &str = "rigid-body impact theory for a contact sliding throughout (Chung & Ooi 2011, Eq. for gross sliding)";

/// Tests 1 and 2: a head-on elastic impact against Hertz theory.
fn hertz_test(number: u8, run: &Runner, impact: Impact, label: &str) -> Result<TestResult, String> {
    let out = run(&impact, time_step(&impact))?;
    let a = &impact.sphere;
    let (r, m, v, y) = match &impact.partner {
        None => (
            a.radius,
            mass(a.material, a.radius),
            -a.velocity.z,
            e_star(a.material, None),
        ),
        Some(b) => (
            a.radius / 2.0,
            mass(a.material, a.radius) / 2.0,
            2.0 * a.velocity.x,
            e_star(a.material, Some(b.material)),
        ),
    };
    let (delta, force, time) = hertz(y, r, m, v);
    let rows = [
        ("largest overlap (m)", out.max_overlap, delta),
        ("largest normal force (N)", out.max_force, force),
        ("contact time (s)", out.contact_time, time),
    ];
    let criteria = rows
        .iter()
        .map(|(name, got, want)| {
            Criterion::new(
                &format!("{name}: gap to Hertz theory (%)"),
                100.0 * rel(*got, *want),
                1.0,
                "the one impact".into(),
                HERTZ,
            )
        })
        .collect();
    let points = rows
        .iter()
        .enumerate()
        .map(|(k, (_, got, want))| Point {
            k: k + 1,
            x: (k + 1) as Real,
            y: got / want,
            closed_form: Some(1.0),
            sliding: false,
        })
        .collect();
    Ok(TestResult {
        number,
        title: if number == 1 {
            "Elastic normal impact of two identical spheres"
        } else {
            "Elastic normal impact of a sphere with a rigid plane"
        },
        inputs: label.into(),
        curves: vec![Curve {
            stem: if number == 1 { "test1" } else { "test2" },
            title: "measured / Hertz theory: 1 overlap, 2 force, 3 contact time",
            x_label: "quantity (1 overlap, 2 force, 3 contact time)",
            y_label: "measured / Hertz theory",
            points,
            reference: None,
        }],
        criteria,
    })
}

pub fn test1(run: &Runner) -> Result<TestResult, String> {
    let r = 0.010;
    let sphere = |x: Real, v: Real| Sphere {
        material: GLASS,
        radius: r,
        position: Vec3::new(x, 0.0, 0.0),
        velocity: Vec3::new(v, 0.0, 0.0),
        omega: Vec3::ZERO,
    };
    let impact = Impact {
        sphere: sphere(-1.01 * r, 10.0),
        partner: Some(sphere(1.01 * r, -10.0)),
        restitution: 1.0,
        friction: 0.0,
    };
    hertz_test(
        1,
        run,
        impact,
        "glass spheres, R = 0.010 m, 10 m/s each, e = 1, no friction",
    )
}

pub fn test2(run: &Runner) -> Result<TestResult, String> {
    let impact = Impact {
        sphere: on_plane(AL_ALLOY, 0.1, Vec3::new(0.0, 0.0, -0.2), Vec3::ZERO),
        partner: None,
        restitution: 1.0,
        friction: 0.0,
    };
    hertz_test(
        2,
        run,
        impact,
        "Al. alloy sphere, R = 0.1 m, 0.2 m/s onto a rigid plane, e = 1, no friction",
    )
}

/// Test 3: restitution in, restitution out.
pub fn test3(run: &Runner) -> Result<TestResult, String> {
    let mut points = Vec::new();
    for (k, e) in [0.2, 0.4, 0.6, 0.8, 1.0].into_iter().enumerate() {
        let impact = Impact {
            sphere: on_plane(AL_OXIDE, 0.0025, Vec3::new(0.0, 0.0, -3.9), Vec3::ZERO),
            partner: None,
            restitution: e,
            friction: 0.0,
        };
        let out = run(&impact, time_step(&impact))?;
        points.push(Point {
            k: k + 1,
            x: e,
            y: out.velocity[0].z / 3.9,
            closed_form: Some(e),
            sliding: false,
        });
    }
    let measured: Vec<Real> = points.iter().map(|p| p.y).collect();
    let given: Vec<Real> = points.iter().map(|p| p.x).collect();
    let criteria = vec![Criterion::new(
        "restitution out against in (%)",
        kratos_error(&measured, &given),
        1.0,
        "e = 0.2, 0.4, 0.6, 0.8, 1.0 (e = 0 is outside the law's range, 0 < e <= 1)".into(),
        "Kratos DEM test 3 (sum |e_out - e_in| / sum e_in, 1%)",
    )];
    Ok(TestResult {
        number: 3,
        title: "Normal contact with different coefficients of restitution",
        inputs: "Al. oxide sphere, R = 2.5 mm, 3.9 m/s onto a rigid plane, no friction".into(),
        curves: vec![Curve {
            stem: "test3",
            title: "restitution out against restitution given",
            x_label: "restitution given",
            y_label: "restitution measured",
            points,
            reference: None,
        }],
        criteria,
    })
}

/// Rigid-body impact with friction on a plane: the contact-point slip `v_t` (along x) changes
/// by `-3.5 mu (1 + e) v_n` when it slides throughout, i.e. when `v_t > 3.5 mu (1 + e) v_n`.
fn slides(v_t: Real, v_n: Real, mu: Real, e: Real) -> bool {
    v_t > 1.2 * 3.5 * mu * (1.0 + e) * v_n
}

/// Test 4: oblique impacts at 3.9 m/s, incident angle 5 to 85 degrees.
pub fn test4(run: &Runner) -> Result<TestResult, String> {
    let (r, mu, e, speed) = (0.0025, 0.092, 0.98, 3.9);
    let mut curves = [
        Vec::new(), // tangential restitution
        Vec::new(), // final spin
        Vec::new(), // rebound angle of the contact point
    ];
    for (k, theta) in angles() {
        let (v_t, v_n) = (speed * theta.sin(), speed * theta.cos());
        let impact = Impact {
            sphere: on_plane(AL_OXIDE, r, Vec3::new(v_t, 0.0, -v_n), Vec3::ZERO),
            partner: None,
            restitution: e,
            friction: mu,
        };
        let out = run(&impact, time_step(&impact))?;
        let (v, w) = (out.velocity[0], out.omega[0]);
        let sliding = slides(v_t, v_n, mu, e);
        let jt = mu * (1.0 + e) * v_n;
        let deg = theta.to_degrees();
        let rigid = [
            (v_t - jt) / v_t,
            2.5 * jt / r,
            ((v_t - 3.5 * jt) / (e * v_n)).atan().to_degrees(),
        ];
        let got = [v.x / v_t, w.y, ((v.x - r * w.y) / v.z).atan().to_degrees()];
        for c in 0..3 {
            curves[c].push(Point {
                k,
                x: deg,
                y: got[c],
                closed_form: sliding.then_some(rigid[c]),
                sliding,
            });
        }
    }
    let [c0, c1, c2] = curves;
    let make = |stem, title, y_label, points| Curve {
        stem,
        title,
        x_label: "incident angle (degrees)",
        y_label,
        points,
        reference: None,
    };
    let curves = vec![
        make(
            "test4_tangential_restitution",
            "tangential restitution v_t'/v_t",
            "v_t'/v_t",
            c0,
        ),
        make("test4_spin", "final angular velocity", "omega' (rad/s)", c1),
        make(
            "test4_rebound_angle",
            "rebound angle of the contact point",
            "rebound angle (degrees)",
            c2,
        ),
    ];
    let criteria = curves
        .iter()
        .map(|c| {
            let (gap, points) = closed_form_gap(c, true);
            Criterion::new(
                &format!("{}: gap to rigid-body sliding (%)", c.title),
                gap,
                2.0,
                points,
                "rigid-body theory where the contact slides throughout; tolerance: Kratos DEM test 4 (2%)",
            )
        })
        .collect();
    Ok(TestResult {
        number: 4,
        title: "Oblique impact of a sphere with a rigid plane at constant speed, different angles",
        inputs: "Al. oxide sphere, R = 2.5 mm, 3.9 m/s at 5-85 degrees, e = 0.98, mu = 0.092"
            .into(),
        curves,
        criteria,
    })
}

/// Kratos's criterion on `curve` against `reference` rows `rows` at Kratos points `ks`.
fn kratos_on(
    curve: &Curve,
    ks: &[usize],
    rows: std::ops::Range<usize>,
    tolerance: Real,
    test: u8,
) -> Criterion {
    let reference = curve.reference.expect("a digitized reference");
    let measured: Vec<Real> = ks
        .iter()
        .map(|k| {
            curve
                .points
                .iter()
                .find(|p| p.k == *k)
                .map_or(Real::NAN, |p| p.y)
        })
        .collect();
    let wanted: Vec<Real> = reference.points[rows.clone()].iter().map(|p| p.1).collect();
    Criterion::new(
        &format!("{}: Kratos error (%)", curve.title),
        kratos_error(&measured, &wanted),
        tolerance,
        format!(
            "k = {:?} against rows {}-{} of {}",
            ks,
            rows.start + 1,
            rows.end,
            reference.label
        ),
        &format!(
            "Kratos DEM test {test} criterion; reference: {}",
            reference.source
        ),
    )
}

fn sliding_criterion(curve: &Curve) -> Criterion {
    let (gap, points) = closed_form_gap(curve, true);
    Criterion::new(
        &format!("{}: gap to rigid-body sliding (%)", curve.title),
        gap,
        1.0,
        points,
        RIGID,
    )
}

/// Test 5: oblique impacts at a constant normal speed (5 m/s), tangential speed 5 tan(theta).
pub fn test5(run: &Runner) -> Result<TestResult, String> {
    let (r, mu, e, v_n) = (1e-5, 0.3, 1.0, 5.0);
    let (mut recoil, mut spin) = (Vec::new(), Vec::new());
    for (k, theta) in angles() {
        let v_t = v_n * theta.tan();
        let impact = Impact {
            sphere: on_plane(STEEL, r, Vec3::new(v_t, 0.0, -v_n), Vec3::ZERO),
            partner: None,
            restitution: e,
            friction: mu,
        };
        let out = run(&impact, time_step(&impact))?;
        let (v, w) = (out.velocity[0], out.omega[0]);
        let x = v_t / (mu * v_n);
        let sliding = slides(v_t, v_n, mu, e);
        recoil.push(Point {
            k,
            x,
            y: (v.x - r * w.y) / (mu * v.z),
            closed_form: sliding.then_some((x - 3.5 * (1.0 + e)) / e),
            sliding,
        });
        spin.push(Point {
            k,
            x,
            y: -r * w.y / (mu * v_n),
            closed_form: sliding.then_some(-2.5 * (1.0 + e)),
            sliding,
        });
    }
    let recoil = Curve {
        stem: "test5_recoil",
        title: "V'_st / (mu V'_cn)",
        x_label: "V_st / (mu V_cn)",
        y_label: "V'_st / (mu V'_cn)",
        points: recoil,
        reference: Some(&reference::TEST5_RECOIL_FEM),
    };
    let spin = Curve {
        stem: "test5_spin",
        title: "-R omega' / (mu V_cn)",
        x_label: "V_st / (mu V_cn)",
        y_label: "-R omega' / (mu V_cn)",
        points: spin,
        reference: Some(&reference::TEST5_SPIN_FEM),
    };
    let ks = [12, 13, 14, 15];
    let criteria = vec![
        kratos_on(&recoil, &ks, 12..16, 2.0, 5),
        kratos_on(&spin, &ks, 12..16, 2.0, 5),
        sliding_criterion(&recoil),
        sliding_criterion(&spin),
    ];
    Ok(TestResult {
        number: 5,
        title:
            "Oblique impact with a rigid plane, constant normal speed, different tangential speeds",
        inputs: "steel sphere, R = 10 um, V_cn = 5 m/s, V_st = 5 tan(5k degrees), e = 1, mu = 0.3"
            .into(),
        curves: vec![recoil, spin],
        criteria,
    })
}

/// Tests 6 and 8's impact: an Al. alloy sphere (R = 0.1 m) at `v_n` along -z, its contact
/// point at -R z sliding along +x at `v_st` from spin alone (`omega_y = -v_st / R`), onto the
/// plane (6) or onto test 8's heavy sphere below it.
fn spinning_impact(number: u8, v_n: Real, v_st: Real, e: Real, mu: Real) -> Impact {
    let r = 0.1;
    let sphere = on_plane(
        AL_ALLOY,
        r,
        Vec3::new(0.0, 0.0, -v_n),
        Vec3::new(0.0, -v_st / r, 0.0),
    );
    let partner = (number == 8).then_some(Sphere {
        material: HEAVY,
        radius: 0.5,
        position: Vec3::new(0.0, 0.0, -0.501),
        velocity: Vec3::ZERO,
        omega: Vec3::ZERO,
    });
    Impact {
        sphere,
        partner,
        restitution: e,
        friction: mu,
    }
}

/// Tests 6 and 8: a spinning sphere (contact-point speed `V_st = v_n tan(theta)` from spin
/// alone) onto a rigid plane (6) or a large, heavy sphere (8).
fn spin_test(run: &Runner, number: u8) -> Result<TestResult, String> {
    let (r, mu, e, v_n) = (0.1, 0.4, 0.5, 0.2);
    let (mut beta, mut recoil) = (Vec::new(), Vec::new());
    for (k, theta) in angles() {
        // Test 8 runs its angles from 85 degrees down (Kratos's order).
        let theta = if number == 8 {
            (90.0 - 5.0 * k as Real).to_radians()
        } else {
            theta
        };
        let v_st = v_n * theta.tan();
        let impact = spinning_impact(number, v_n, v_st, e, mu);
        let out = run(&impact, time_step(&impact))?;
        let (v, w) = (out.velocity[0], out.omega[0]);
        let v_st_out = v.x - r * w.y;
        let sliding = slides(v_st, v_n, mu, e);
        let special = 3.5 * mu * (1.0 + e) * v_n / v_st;
        beta.push(Point {
            k,
            x: special,
            y: -v_st_out / v_st,
            closed_form: sliding.then_some(special - 1.0),
            sliding,
        });
        recoil.push(Point {
            k,
            x: v_st / v_n,
            y: v_st_out / v.z,
            closed_form: sliding.then_some((v_st / v_n - 3.5 * mu * (1.0 + e)) / e),
            sliding,
        });
    }
    let (r1, r2) = if number == 6 {
        (&reference::TEST6_BETA, &reference::TEST6_RECOIL)
    } else {
        (&reference::TEST8_BETA, &reference::TEST8_RECOIL)
    };
    let beta = Curve {
        stem: if number == 6 {
            "test6_beta"
        } else {
            "test8_beta"
        },
        title: "beta = -V'_st / V_st",
        x_label: "3.5 mu (1 + e) V_cn / V_st",
        y_label: "beta",
        points: beta,
        reference: Some(r1),
    };
    let recoil = Curve {
        stem: if number == 6 {
            "test6_recoil"
        } else {
            "test8_recoil"
        },
        title: "tangent of the recoil angle V'_st / V'_cn",
        x_label: "V_st / V_cn (tangent of the incident angle)",
        y_label: "V'_st / V'_cn",
        points: recoil,
        reference: Some(r2),
    };
    let criteria = if number == 6 {
        vec![
            kratos_on(&beta, &[17, 16, 15, 14, 13, 12], 0..6, 3.0, 6),
            kratos_on(&recoil, &[13, 14, 15, 16], 12..16, 3.0, 6),
            sliding_criterion(&beta),
            sliding_criterion(&recoil),
        ]
    } else {
        vec![
            kratos_on(&beta, &[1, 2, 3, 4, 5, 6], 0..6, 3.0, 8),
            kratos_on(&recoil, &[5, 4, 3, 2], 12..16, 3.0, 8),
            sliding_criterion(&beta),
            sliding_criterion(&recoil),
        ]
    };
    Ok(TestResult {
        number,
        title: if number == 6 {
            "Impact of a spinning sphere with a rigid plane, constant normal speed"
        } else {
            "Impact of a spinning sphere with a larger sphere, constant normal speed"
        },
        inputs: format!(
            "Al. alloy sphere, R = 0.1 m, V_cn = 0.2 m/s, V_st = 0.2 tan(theta) from spin alone, e = 0.5, mu = 0.4{}",
            if number == 8 { "; the partner: R = 0.5 m, 1000 x the density and Young's modulus, at rest (Kratos benchmark8DEM.mdpa)" } else { "" }
        ),
        curves: vec![beta, recoil],
        criteria,
    })
}

pub fn test6(run: &Runner) -> Result<TestResult, String> {
    spin_test(run, 6)
}

pub fn test8(run: &Runner) -> Result<TestResult, String> {
    spin_test(run, 8)
}

/// Test 7: two identical spheres, head-on at 0.2 m/s each, spinning oppositely: their contact
/// points move together, so nothing slides and the spins and tangential speeds stay.
pub fn test7(run: &Runner) -> Result<TestResult, String> {
    let (r, v) = (0.1, 0.2);
    let (mut vt, mut spin) = (Vec::new(), Vec::new());
    for (k, theta) in angles() {
        let w = v / r * theta.tan();
        let sphere = |x: Real, s: Real| Sphere {
            material: AL_ALLOY,
            radius: r,
            position: Vec3::new(x, 0.0, 0.0),
            velocity: Vec3::new(s * v, 0.0, 0.0),
            omega: Vec3::new(0.0, s * w, 0.0),
        };
        let impact = Impact {
            sphere: sphere(-1.01 * r, 1.0),
            partner: Some(sphere(1.01 * r, -1.0)),
            restitution: 0.5,
            friction: 0.4,
        };
        let out = run(&impact, time_step(&impact))?;
        vt.push(Point {
            k,
            x: w,
            y: out.velocity[0].z,
            closed_form: Some(0.0),
            sliding: false,
        });
        spin.push(Point {
            k,
            x: w,
            y: out.omega[0].y,
            closed_form: Some(w),
            sliding: false,
        });
    }
    let kratos_vt = 100.0 * vt.iter().map(|p| p.y.abs()).sum::<Real>();
    let spins: Vec<Real> = spin.iter().map(|p| p.y).collect();
    let given: Vec<Real> = spin.iter().map(|p| p.x).collect();
    let all = "k = 1..17".to_string();
    let criteria = vec![
        Criterion::new(
            "final tangential speed: 100 sum |v_t'| (Kratos units)",
            kratos_vt,
            1.0,
            all.clone(),
            "Kratos DEM test 7 (reference: 0, by symmetry)",
        ),
        Criterion::new(
            "final spin: Kratos error (%)",
            kratos_error(&spins, &given),
            1.0,
            all,
            "Kratos DEM test 7 (reference: the initial spin, by symmetry)",
        ),
    ];
    let curve = |stem, title, y_label, points| Curve {
        stem,
        title,
        x_label: "initial spin (rad/s)",
        y_label,
        points,
        reference: None,
    };
    Ok(TestResult {
        number: 7,
        title: "Impact of two identical spheres spinning oppositely, constant normal speed",
        inputs: "Al. alloy spheres, R = 0.1 m, 0.2 m/s each, spin 2 tan(5k degrees) rad/s, e = 0.5, mu = 0.4".into(),
        curves: vec![
            curve("test7_tangential_speed", "final tangential speed", "v_t' (m/s)", vt),
            curve("test7_spin", "final spin", "omega' (rad/s)", spin),
        ],
        criteria,
    })
}
