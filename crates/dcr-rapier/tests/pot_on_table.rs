//! The `pot_on_table` example's scene: the plates jump only with the response on.
//!
//! Expectation: with the table's baked base (20 modes, paper Table 2 material), the 5 kg pot's
//! impact lifts the largest plate by more than 1 mm with the response on, and not at all with it
//! off (the plates rest away from the pot); the table sees the same impacts either way. The base
//! is baked once into `CARGO_TARGET_TMPDIR` (rebaked only when stale).

#[path = "../examples/pot_on_table.rs"]
mod pot_on_table;

use dcr_rapier::ModalModel;

#[test]
fn plates_jump_only_with_the_response() {
    let bases = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("bases");
    let (path, _) = pot_on_table::table_base(&bases).expect("table base bakes");
    let model = ModalModel::load(&path).expect("base loads");
    let on = pot_on_table::run(&model, true).expect("on run");
    let off = pot_on_table::run(&model, false).expect("off run");
    assert!(
        on.impacts > 0 && on.impacts == off.impacts,
        "{on:?} vs {off:?}"
    );
    assert!(on.events > 0, "responses reach the plates: {on:?}");
    assert!(
        on.lift_mm > 1.0 && on.lift_mm > off.lift_mm,
        "lift on {} mm vs off {} mm",
        on.lift_mm,
        off.lift_mm
    );
    assert!(
        off.lift_mm < 0.05,
        "plates rest without the response: {} mm",
        off.lift_mm
    );
}
