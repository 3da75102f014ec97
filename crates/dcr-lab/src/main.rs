//! `dcr-lab`: full-order truth, the attenuation fit and the accuracy report. See `dcr-lab --help`.
//!
//! Defines the C library's `rand` and `srand` for the METIS it links through `modal-bake`
//! (`modal_bake::c_rand_symbols!`: the same fill-reducing orders as `modal-bake` on every
//! platform).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}

modal_bake::c_rand_symbols!();
