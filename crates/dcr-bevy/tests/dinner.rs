//! The `dinner` example's scene in a headless Bevy app: the plates jump only with [`DcrPlugin`],
//! the responses arrive as Bevy messages, and their impulses survive bevy_rapier's writeback on
//! bodies with a `Velocity` component.
//!
//! The table's base (20 modes, the paper's Table 2 material) is baked once into
//! `CARGO_TARGET_TMPDIR` (rebaked only when stale) and loaded through the `.modes` asset loader.

#[path = "../examples/dinner.rs"]
mod dinner;

use std::path::PathBuf;
use std::sync::OnceLock;

use dinner::{DinnerOptions, DinnerOutcome, PLATE_MASS};

/// 0.8 s: the pot lands at ≈ 0.3 s and the plates have jumped and landed by then.
const STEPS: u32 = 80;

fn bases() -> PathBuf {
    static BASES: OnceLock<PathBuf> = OnceLock::new();
    BASES
        .get_or_init(|| {
            let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bases");
            dinner::table_base(&dir).expect("the table's base bakes");
            dir
        })
        .clone()
}

fn run(response: bool, plate_velocity: bool) -> DinnerOutcome {
    dinner::run(
        &bases(),
        DinnerOptions {
            response,
            plate_velocity,
            steps: STEPS,
        },
    )
    .expect("the scene runs")
}

#[test]
fn plates_jump_with_the_plugin_and_not_without() {
    let on = run(true, false);
    let off = run(false, false);
    let status = on.status.clone().expect("the plugin reports");
    assert_eq!(status.refused_steps, 0, "{status:?}");
    assert!(status.steps >= u64::from(STEPS), "{status:?}");
    assert!(on.plate_events > 0, "responses reach the plates: {on:?}");
    assert!(
        on.lift_mm > 1.0,
        "the plates jump with the plugin: {} mm",
        on.lift_mm
    );
    assert!(
        off.lift_mm < 0.05,
        "the plates rest without it: {} mm",
        off.lift_mm
    );
    assert!(off.status.is_none() && off.events == 0);
}

#[test]
fn responses_arrive_as_messages_from_the_table_to_the_plates() {
    let on = run(true, false);
    assert!(!on.messages.is_empty());
    assert_eq!(on.messages.len() as u64, on.status.unwrap().total_events);
    let table = on.messages[0].object;
    let mut supports = 0;
    for m in &on.messages {
        assert_eq!(m.object, table, "one elastic object: {m:?}");
        assert_ne!(m.body, table, "{m:?}");
        // The table top's outward normal is +y; the push is along it, up.
        assert!(m.normal.y > 0.99, "{m:?}");
        assert!(m.impulse.dot(m.normal) > 0.0, "{m:?}");
        assert!(m.point.x.abs() <= 0.8 && m.point.z.abs() <= 0.45, "{m:?}");
        if m.delta_v > 0.0 {
            // A response: applied at the contact, on the table top (y = 0.75 m).
            assert!((m.point.y - 0.75).abs() < 0.01, "{m:?}");
        } else {
            // The support of a plate the response lifts off (bevy_rapier's gravity, which the
            // plugin gives the world): m g h up, at the plate's centre of mass.
            supports += 1;
            let mgh = PLATE_MASS * 9.81 * dinner::H as f32;
            assert!((m.impulse.y - mgh).abs() < 1e-3 * mgh, "{m:?}");
            assert!((m.point.y - dinner::PLATE_Y).abs() < 0.01, "{m:?}");
        }
    }
    assert!(supports > 0, "lifted plates get their support");
    // The plates receive responses (the pot, once resting, may too).
    assert!(on.plate_events > 0 && on.plate_events <= on.events);
}

#[test]
fn impulses_survive_the_writeback_of_velocity_components() {
    let with = run(true, true);
    assert!(!with.velocity_checks.is_empty(), "{with:?}");
    for c in &with.velocity_checks {
        let v = c.component.expect("the plates carry a Velocity component");
        // The writeback copied rapier's velocity, response included.
        assert_eq!(v, c.rapier, "{c:?}");
        // The whole response is in it: Δv = ΣJ / m (linear part of apply_impulse_at_point).
        let expected = c.impulse / PLATE_MASS;
        let got = v - c.after_step;
        assert!(
            (got - expected).length() <= 1e-4 + 1e-3 * expected.length(),
            "velocity change {got} vs ΣJ/m = {expected}: {c:?}"
        );
    }
    assert!(
        with.lift_mm > 1.0,
        "plates with a Velocity component jump too: {} mm",
        with.lift_mm
    );
    let without = run(true, false);
    assert!(
        (with.lift_mm - without.lift_mm).abs() <= 0.1 * without.lift_mm,
        "a Velocity component does not change the jump: {} vs {} mm",
        with.lift_mm,
        without.lift_mm
    );
}
