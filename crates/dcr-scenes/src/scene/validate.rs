//! Validation of a parsed scene ([`SceneDesc::validate`]): every number in its working range,
//! every name a plain file-name component or a body that exists, the run's size bounded —
//! before a world is built, a base baked or a file written. Each refusal names the field by its
//! path in the file (`props[1].mass`) and the range that works.

use std::collections::BTreeSet;

use super::scene_desc::{
    name_matches, BodyKind, ColliderDesc, ElasticDesc, MethodDesc, PoseDesc, SceneDesc, ShapeDesc,
    TransferDesc,
};

/// Largest |coordinate| of a pose, copy, anchor or point (m).
pub const MAX_POSITION_M: f64 = 1e5;
/// Largest collider size (half extent, radius, hull point; m).
pub const MAX_SIZE_M: f64 = 1e4;
/// Smallest collider size (half extent, radius; m).
pub const MIN_SIZE_M: f64 = 1e-4;
/// Largest |velocity| (m/s) and |angular velocity| (rad/s) of a prop.
pub const MAX_SPEED: f64 = 1e4;
/// Largest |gravity| (m/s²).
pub const MAX_GRAVITY: f64 = 1e3;
/// Step h range (s).
pub const H_RANGE_S: (f64, f64) = (1e-5, 0.1);
/// Largest number of steps of a run (`seconds / h`).
pub const MAX_STEPS: f64 = 1e6;
/// Largest number of bodies of a scene (elastic objects and prop copies).
pub const MAX_BODIES: usize = 100_000;
/// Largest steps × recorded bodies of a run (the trajectory holds 7 `f64` per body and row).
pub const MAX_STEP_BODIES: f64 = 2e7;
/// Mass range of a body (kg).
pub const MASS_RANGE_KG: (f64, f64) = (1e-6, 1e9);

/// The outcome kinds a scene may ask for.
pub const OUTCOME_KINDS: [&str; 7] = [
    "max_lift",
    "max_slide",
    "max_tilt",
    "count_fallen",
    "max_sway",
    "sway_range",
    "count_moved",
];

type Check = Result<(), String>;

/// A number in messages: plain when moderate, else in exponent form (`1e300`, not 301 digits).
struct N(f64);

impl std::fmt::Display for N {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v != 0.0 && v.is_finite() && !(1e-4..1e7).contains(&v.abs()) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

fn finite_in(field: &str, v: f64, lo: f64, hi: f64, unit: &str) -> Check {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(format!(
            "{field} must be in [{}, {}]{unit} (got {})",
            N(lo),
            N(hi),
            N(v)
        ))
    }
}

fn positive_max(field: &str, v: f64, hi: f64, unit: &str) -> Check {
    if v.is_finite() && v > 0.0 && v <= hi {
        Ok(())
    } else {
        Err(format!(
            "{field} must be > 0{unit} and ≤ {}{unit} (got {})",
            N(hi),
            N(v)
        ))
    }
}

fn vec_in(field: &str, v: [f64; 3], bound: f64, unit: &str) -> Check {
    for (k, x) in v.iter().enumerate() {
        if !(x.is_finite() && x.abs() <= bound) {
            return Err(format!(
                "{field}[{k}] must be a finite number within ±{}{unit} (got {})",
                N(bound),
                N(*x)
            ));
        }
    }
    Ok(())
}

fn nonzero_axis(field: &str, v: [f64; 3]) -> Check {
    vec_in(field, v, 1e6, "")?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 1e-9 {
        Ok(())
    } else {
        Err(format!(
            "{field} must be a non-zero direction (got [{}, {}, {}])",
            v[0], v[1], v[2]
        ))
    }
}

fn pose(field: &str, p: &PoseDesc) -> Check {
    vec_in(
        &format!("{field}.translation"),
        p.translation,
        MAX_POSITION_M,
        " m",
    )?;
    vec_in(
        &format!("{field}.rotation_deg"),
        p.rotation_deg,
        3600.0,
        "°",
    )
}

/// Whether `name` is a plain file-name component: 1 to 100 bytes, no `/`, `\`, NUL or
/// control character, not starting with `.` (no hidden files, no `.` or `..`).
pub fn is_plain_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 100
        && !name.starts_with('.')
        && !name
            .chars()
            .any(|c| c == '/' || c == '\\' || c.is_control() || c == '*')
}

fn plain_name(field: &str, name: &str) -> Check {
    if is_plain_name(name) {
        Ok(())
    } else {
        Err(format!(
            "{field} {name:?} must be a plain file name (1 to 100 characters, no '/', '\\', '*' \
             or control characters, not starting with '.'), e.g. \"table\""
        ))
    }
}

fn shape(field: &str, s: &ShapeDesc) -> Check {
    let size =
        |f: &str, v: f64| finite_in(&format!("{field}.{f}"), v, MIN_SIZE_M, MAX_SIZE_M, " m");
    match s {
        ShapeDesc::Cuboid { half_extents } => {
            for (k, &h) in half_extents.iter().enumerate() {
                size(&format!("cuboid.half_extents[{k}]"), h)?;
            }
            Ok(())
        }
        ShapeDesc::Ball { radius } => size("ball.radius", *radius),
        ShapeDesc::Cylinder {
            half_height,
            radius,
        } => {
            size("cylinder.half_height", *half_height)?;
            size("cylinder.radius", *radius)
        }
        ShapeDesc::Cone {
            half_height,
            radius,
        } => {
            size("cone.half_height", *half_height)?;
            size("cone.radius", *radius)
        }
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => {
            size("capsule.half_height", *half_height)?;
            size("capsule.radius", *radius)
        }
        ShapeDesc::ConvexHull { points } => {
            if points.len() < 4 || points.len() > 10_000 {
                return Err(format!(
                    "{field}.convex_hull.points must hold 4 to 10000 points (got {})",
                    points.len()
                ));
            }
            for (i, p) in points.iter().enumerate() {
                vec_in(
                    &format!("{field}.convex_hull.points[{i}]"),
                    *p,
                    MAX_SIZE_M,
                    " m",
                )?;
            }
            Ok(())
        }
    }
}

fn colliders(field: &str, cs: &[ColliderDesc]) -> Check {
    if cs.is_empty() {
        return Err(format!(
            "{field} must hold at least one collider (e.g. {{\"shape\": {{\"ball\": {{\"radius\": 0.1}}}}}})"
        ));
    }
    if cs.len() > 1000 {
        return Err(format!(
            "{field} holds {} colliders (at most 1000)",
            cs.len()
        ));
    }
    for (i, c) in cs.iter().enumerate() {
        shape(&format!("{field}[{i}].shape"), &c.shape)?;
        pose(&format!("{field}[{i}].offset"), &c.offset)?;
    }
    Ok(())
}

/// Most fixed-node selectors of one kind (half-spaces or boxes) per elastic object.
const MAX_FIXED_SELECTORS: usize = 64;

/// The fixed-node selectors of elastic object `e` (field prefix `field`): finite values within
/// the scene's extent, boxes with each minimum ≤ its maximum, at most
/// [`MAX_FIXED_SELECTORS`] of each kind. Whether they fix any node is the bake's check (it
/// reads the mesh).
fn fixed_selectors(field: &str, e: &ElasticDesc) -> Check {
    if e.fixed_below.len() > MAX_FIXED_SELECTORS || e.fixed_boxes.len() > MAX_FIXED_SELECTORS {
        return Err(format!(
            "{field}: at most {MAX_FIXED_SELECTORS} fixed_below and {MAX_FIXED_SELECTORS} fixed_boxes (got {} and {})",
            e.fixed_below.len(),
            e.fixed_boxes.len()
        ));
    }
    for (i, b) in e.fixed_below.iter().enumerate() {
        if !(b.value.is_finite() && b.value.abs() <= MAX_POSITION_M) {
            return Err(format!(
                "{field}.fixed_below[{i}].value must be finite within ±{MAX_POSITION_M} m (got {})",
                b.value
            ));
        }
    }
    aabbs(&format!("{field}.fixed_boxes"), &e.fixed_boxes)?;
    Ok(())
}

/// Axis-aligned boxes `[xmin, ymin, zmin, xmax, ymax, zmax]` (m) at `field`: finite within
/// ±[`MAX_POSITION_M`], each minimum ≤ its maximum.
fn aabbs(field: &str, boxes: &[[f64; 6]]) -> Check {
    for (i, b) in boxes.iter().enumerate() {
        for (k, x) in b.iter().enumerate() {
            if !(x.is_finite() && x.abs() <= MAX_POSITION_M) {
                return Err(format!(
                    "{field}[{i}][{k}] must be finite within ±{MAX_POSITION_M} m (got {x})"
                ));
            }
        }
        for k in 0..3 {
            if b[k] > b[k + 3] {
                return Err(format!(
                    "{field}[{i}] must be [xmin, ymin, zmin, xmax, ymax, zmax] with each min ≤ max (got {} > {})",
                    b[k],
                    b[k + 3]
                ));
            }
        }
    }
    Ok(())
}

fn transfer(field: &str, t: &TransferDesc) -> Check {
    if let Some(up) = t.up {
        nonzero_axis(&format!("{field}.up"), up)?;
    }
    aabbs(&format!("{field}.boxes"), &t.boxes)?;
    if t.modes == Some(0) {
        return Err(format!("{field}.modes must be ≥ 1 (got 0)"));
    }
    if let Some(h) = t.h {
        finite_in(&format!("{field}.h"), h, H_RANGE_S.0, H_RANGE_S.1, " s")?;
    }
    Ok(())
}

fn method(field: &str, m: &MethodDesc) -> Check {
    match m {
        MethodDesc::Modal => Ok(()),
        MethodDesc::Attenuation {
            c,
            beta,
            distance,
            amplitude,
        } => {
            finite_in(&format!("{field}.attenuation.c"), *c, 0.0, 1e6, "")?;
            finite_in(&format!("{field}.attenuation.beta"), *beta, 0.0, 10.0, "")?;
            if !["heat", "heat_table", "euclidean"].contains(&distance.as_str()) {
                return Err(format!(
                    "{field}.attenuation.distance {distance:?} must be \"heat\", \"heat_table\" or \"euclidean\""
                ));
            }
            if amplitude.is_empty() {
                return Err(format!(
                    "{field}.attenuation.amplitude must be \"per_vertex\", \"mean\" or a physical group of the mesh"
                ));
            }
            Ok(())
        }
        MethodDesc::Transfer(t) => transfer(&format!("{field}.transfer"), t),
    }
}

/// Half the thinnest dimension of a shape (m): its half extent, radius or half height, the
/// least of them. For a convex hull, half the smallest side of its bounding box.
fn half_thickness(s: &ShapeDesc) -> f64 {
    match s {
        ShapeDesc::Cuboid { half_extents } => half_extents.iter().copied().fold(f64::MAX, f64::min),
        ShapeDesc::Ball { radius } => *radius,
        ShapeDesc::Cylinder {
            half_height,
            radius,
        }
        | ShapeDesc::Cone {
            half_height,
            radius,
        } => half_height.min(*radius),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => half_height + radius,
        ShapeDesc::ConvexHull { points } => (0..3)
            .map(|k| {
                let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                    (lo.min(p[k]), hi.max(p[k]))
                });
                0.5 * (hi - lo)
            })
            .fold(f64::MAX, f64::min),
    }
}

/// Copies of a prop must not start inside each other: two copies closer than the prop's
/// thinnest collider (its half thickness, the largest over its colliders) would start deeply
/// interpenetrating, and thousands of them make the contact solver's memory explode.
fn copies_apart(field: &str, p: &super::scene_desc::PropDesc) -> Check {
    if p.copies.len() < 2 {
        return Ok(());
    }
    let min_gap = p
        .colliders
        .iter()
        .map(|c| half_thickness(&c.shape))
        .fold(0.0, f64::max);
    let mut order: Vec<usize> = (0..p.copies.len()).collect();
    order.sort_by(|&a, &b| p.copies[a][0].total_cmp(&p.copies[b][0]));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            let (pa, pb) = (p.copies[a], p.copies[b]);
            if pb[0] - pa[0] >= min_gap {
                break;
            }
            let d = ((pa[0] - pb[0]).powi(2) + (pa[1] - pb[1]).powi(2) + (pa[2] - pb[2]).powi(2))
                .sqrt();
            if d < min_gap {
                let (i, j) = (a.min(b), a.max(b));
                return Err(format!(
                    "{field}.copies[{i}] and {field}.copies[{j}] are {} m apart: copies must be at \
                     least the prop's half thickness ({} m) apart, or they start inside each other",
                    N(d),
                    N(min_gap)
                ));
            }
        }
    }
    Ok(())
}

impl SceneDesc {
    /// Every body name of the built world (elastic objects, then props with copies as
    /// `name_i`), with whether it is recorded in the trajectory (dynamic).
    pub fn body_names(&self) -> Vec<(String, bool)> {
        let mut names: Vec<(String, bool)> = self
            .elastic
            .iter()
            .map(|e| (e.name.clone(), matches!(e.body, BodyKind::Dynamic { .. })))
            .collect();
        for p in &self.props {
            if p.copies.is_empty() {
                names.push((p.name.clone(), !p.fixed));
            } else {
                names.extend((0..p.copies.len()).map(|i| (format!("{}_{i}", p.name), !p.fixed)));
            }
        }
        names
    }

    /// The number of steps of a run of `seconds` (the scene's `seconds` when `None`), checked
    /// against [`MAX_STEPS`] and, times the recorded bodies, [`MAX_STEP_BODIES`].
    ///
    /// # Errors
    /// A message naming `--seconds` (when given) or `seconds`, with the limit.
    pub fn run_steps(&self, seconds: Option<f64>) -> Result<usize, String> {
        let (field, s) = match seconds {
            Some(s) => ("--seconds", s),
            None => ("seconds", self.seconds),
        };
        if !(s.is_finite() && s > 0.0) {
            return Err(format!(
                "{field} must be a finite time > 0 s (got {})",
                N(s)
            ));
        }
        let steps = (s / self.h).round();
        let recorded = self.body_names().iter().filter(|(_, r)| *r).count().max(1) as f64;
        let max_s = (MAX_STEPS * self.h).min(MAX_STEP_BODIES / recorded * self.h);
        if !(steps <= MAX_STEPS && (steps + 1.0) * recorded <= MAX_STEP_BODIES) {
            return Err(format!(
                "{field} {} s is {} steps of h = {} s for {recorded} recorded bodies; \
                 at most {MAX_STEPS:.0e} steps and {MAX_STEP_BODIES:.0e} steps × bodies: give at \
                 most {max_s:.4} s",
                N(s),
                N(steps),
                self.h
            ));
        }
        Ok(steps.max(1.0) as usize)
    }

    /// Checks every field of the scene (see the module docs).
    ///
    /// # Errors
    /// The first field out of range, as `FIELD must be …` (`props[1].mass must be > 0 kg …`).
    pub fn validate(&self) -> Result<(), String> {
        plain_name("name", &self.name)?;
        finite_in("h", self.h, H_RANGE_S.0, H_RANGE_S.1, " s")?;
        vec_in("gravity", self.gravity, MAX_GRAVITY, " m/s²")?;
        finite_in("restitution", self.restitution, 0.0, 1.0, "")?;
        let bodies = self.body_names();
        if bodies.len() > MAX_BODIES {
            return Err(format!(
                "the scene has {} bodies (elastic objects and prop copies); at most {MAX_BODIES}",
                bodies.len()
            ));
        }
        if let Some(t) = self.test_seconds {
            self.run_steps(Some(t))
                .map_err(|e| e.replacen("--seconds", "test_seconds", 1))?;
        }
        self.run_steps(None)?;
        if self.elastic.is_empty() {
            return Err("elastic must hold at least one elastic object".into());
        }
        for (i, e) in self.elastic.iter().enumerate() {
            let f = format!("elastic[{i}]");
            plain_name(&format!("{f}.name"), &e.name)?;
            if e.mesh.is_empty() {
                return Err(format!("{f}.mesh must be a mesh path"));
            }
            let m = &e.material;
            positive_max(&format!("{f}.material.youngs"), m.youngs, 1e13, " Pa")?;
            if !(m.poisson.is_finite() && m.poisson > -1.0 && m.poisson < 0.5) {
                return Err(format!(
                    "{f}.material.poisson must be in (-1, 0.5) (got {})",
                    m.poisson
                ));
            }
            positive_max(&format!("{f}.material.density"), m.density, 1e6, " kg/m³")?;
            fixed_selectors(&f, e)?;
            if e.modes == 0 || e.modes > 2000 {
                return Err(format!("{f}.modes must be in [1, 2000] (got {})", e.modes));
            }
            finite_in(&format!("{f}.rayleigh[0]"), e.rayleigh[0], 0.0, 1e6, " 1/s")?;
            finite_in(&format!("{f}.rayleigh[1]"), e.rayleigh[1], 0.0, 1.0, " s")?;
            if let BodyKind::Dynamic { mass } = e.body {
                finite_in(
                    &format!("{f}.body.dynamic.mass"),
                    mass,
                    MASS_RANGE_KG.0,
                    MASS_RANGE_KG.1,
                    " kg",
                )?;
            }
            pose(&format!("{f}.pose"), &e.pose)?;
            if let Some(cs) = &e.colliders {
                colliders(&format!("{f}.colliders"), cs)?;
            }
            finite_in(&format!("{f}.friction"), e.friction, 0.0, 100.0, "")?;
            method(&format!("{f}.method"), &e.method)?;
            if let Some(a) = &e.attenuation {
                if !matches!(a, MethodDesc::Attenuation { .. }) {
                    return Err(format!(
                        "{f}.attenuation must be {{\"attenuation\": {{\"c\": …, \"beta\": …}}}}"
                    ));
                }
                method(&format!("{f}.attenuation"), a)?;
            }
            if let Some(t) = &e.transfer {
                transfer(&format!("{f}.transfer"), t)?;
            }
            finite_in(
                &format!("{f}.impact_threshold"),
                e.impact_threshold,
                0.0,
                1e9,
                " N·s",
            )?;
            finite_in(&format!("{f}.gain"), e.gain, 0.0, 1e3, "")?;
        }
        for (i, p) in self.props.iter().enumerate() {
            let f = format!("props[{i}]");
            if p.name.is_empty() || p.name.contains('*') {
                return Err(format!(
                    "{f}.name {:?} must be a non-empty name without '*'",
                    p.name
                ));
            }
            colliders(&format!("{f}.colliders"), &p.colliders)?;
            finite_in(
                &format!("{f}.mass"),
                p.mass,
                MASS_RANGE_KG.0,
                MASS_RANGE_KG.1,
                " kg",
            )?;
            pose(&format!("{f}.pose"), &p.pose)?;
            for (k, c) in p.copies.iter().enumerate() {
                vec_in(&format!("{f}.copies[{k}]"), *c, MAX_POSITION_M, " m")?;
            }
            finite_in(&format!("{f}.friction"), p.friction, 0.0, 100.0, "")?;
            vec_in(&format!("{f}.linvel"), p.linvel, MAX_SPEED, " m/s")?;
            vec_in(&format!("{f}.angvel"), p.angvel, MAX_SPEED, " rad/s")?;
            finite_in(
                &format!("{f}.linear_damping"),
                p.linear_damping,
                0.0,
                1e3,
                " 1/s",
            )?;
            finite_in(
                &format!("{f}.angular_damping"),
                p.angular_damping,
                0.0,
                1e3,
                " 1/s",
            )?;
            copies_apart(&f, p)?;
            if let Some(r) = &p.relative_to {
                if !self.elastic.iter().any(|e| &e.name == r) {
                    return Err(format!("{f}.relative_to {r:?} names no elastic object"));
                }
            }
        }
        let mut seen = BTreeSet::new();
        for (name, _) in &bodies {
            if !seen.insert(name.as_str()) {
                return Err(format!(
                    "two bodies are named {name:?} (names of elastic objects, props and prop \
                     copies `NAME_i` must be unique)"
                ));
            }
        }
        let exists = |pattern: &str, recorded_only: bool| {
            bodies
                .iter()
                .any(|(n, r)| (*r || !recorded_only) && name_matches(pattern, n))
        };
        for (i, j) in self.joints.iter().enumerate() {
            let f = format!("joints[{i}]");
            if !bodies.iter().any(|(n, _)| n == &j.body1) {
                return Err(format!("{f}.body1 {:?} names no body", j.body1));
            }
            if !exists(&j.body2, false) {
                return Err(format!("{f}.body2 {:?} matches no body", j.body2));
            }
            if name_matches(&j.body2, &j.body1) {
                return Err(format!(
                    "{f}: body {:?} cannot be jointed to itself (body2 {:?} matches body1)",
                    j.body1, j.body2
                ));
            }
            vec_in(
                &format!("{f}.anchor_offset"),
                j.anchor_offset,
                MAX_POSITION_M,
                " m",
            )?;
            nonzero_axis(&format!("{f}.axis"), j.axis)?;
            finite_in(
                &format!("{f}.stiffness"),
                j.stiffness,
                0.0,
                1e12,
                " N·m/rad",
            )?;
            finite_in(&format!("{f}.damping"), j.damping, 0.0, 1e12, " N·m·s/rad")?;
        }
        for (i, d) in self.drivers.iter().enumerate() {
            let f = format!("drivers[{i}]");
            if !bodies.iter().any(|(n, r)| *r && n == &d.body) {
                return Err(format!("{f}.body {:?} names no dynamic body", d.body));
            }
            finite_in(&format!("{f}.start"), d.start, 0.0, 1e9, " s")?;
            if d.stop.is_nan() || d.stop < d.start {
                return Err(format!(
                    "{f}.stop must be ≥ start ({} s) (got {})",
                    d.start, d.stop
                ));
            }
            if !(d.period.is_finite() && d.period >= self.h) {
                return Err(format!(
                    "{f}.period must be ≥ the step h = {} s (got {})",
                    self.h, d.period
                ));
            }
            vec_in(&format!("{f}.impulse"), d.impulse, 1e9, " N·s")?;
            if let Some(ax) = d.rotate_axis {
                nonzero_axis(&format!("{f}.rotate_axis"), ax)?;
            }
            finite_in(&format!("{f}.hz"), d.hz, 0.0, 1e4, " Hz")?;
            if let Some(p) = d.point {
                vec_in(&format!("{f}.point"), p, MAX_SIZE_M, " m")?;
            }
        }
        let mut outcome_names = BTreeSet::new();
        for (i, o) in self.outcomes.iter().enumerate() {
            let f = format!("outcomes[{i}]");
            if o.name.is_empty() || !outcome_names.insert(o.name.as_str()) {
                return Err(format!(
                    "{f}.name {:?} must be a non-empty name no other outcome has",
                    o.name
                ));
            }
            if !OUTCOME_KINDS.contains(&o.kind.as_str()) {
                return Err(format!(
                    "{f}.kind {:?} is unknown (kinds: {})",
                    o.kind,
                    OUTCOME_KINDS.join(", ")
                ));
            }
            if !exists(&o.bodies, true) {
                return Err(format!(
                    "{f}.bodies {:?} matches no dynamic body (outcomes measure recorded bodies: dynamic elastic objects and props that are not fixed)",
                    o.bodies
                ));
            }
            positive_max(&format!("{f}.threshold"), o.threshold, 1e6, " m")?;
            if let Some(r) = &o.relative_to {
                if !bodies.iter().any(|(n, rec)| *rec && n == r) {
                    return Err(format!("{f}.relative_to {r:?} names no dynamic body"));
                }
            }
            if !(o.after.is_finite() && o.after >= 0.0) {
                return Err(format!(
                    "{f}.after must be a finite time ≥ 0 s (got {})",
                    o.after
                ));
            }
        }
        Ok(())
    }
}
