//! `modal-bake`: bake, inspect and check `.modes` bases. See `modal-bake --help`.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
