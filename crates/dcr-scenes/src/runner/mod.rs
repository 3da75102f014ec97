//! The headless runner: build a scene's world, step it with the response on or off, record
//! trajectories and timings, measure the scene's outcome figures, write NPZ + JSON.

mod bases;
mod outcomes;
mod run;
mod stress_bench;
mod table1;
mod trajectory;

pub use bases::{
    bake_params, base_path, ensure_base, ensure_transfer_base, surface_base_path,
    transfer_base_path, transfer_params,
};
pub use outcomes::{measure_outcome, unit_of};
pub use run::{
    apply_driver, run_scene, BodyReceived, MethodChoice, ModelReport, ModelStats, ResponseEvent,
    RunParams, RunReport, StepTime, RUN_OUTPUTS,
};
pub use stress_bench::{stress_bench, StressBenchParams};
pub use table1::{paper_rows, table1, PaperRow, Table1Params};
pub use trajectory::Trajectory;
