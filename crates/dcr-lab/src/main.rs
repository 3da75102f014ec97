//! `dcr-lab`: full-order truth, the attenuation fit and the accuracy report. See `dcr-lab --help`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
