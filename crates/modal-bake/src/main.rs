//! `modal-bake`: bake, inspect and check `.modes` bases. See `modal-bake --help`.
//!
//! Also defines the C library's `rand` and `srand` for the METIS this program links statically
//! (`modal_bake::c_rand_symbols!`: glibc's generator, so a mesh gets the same fill-reducing
//! orders, and so the same base, on every platform).

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}

modal_bake::c_rand_symbols!();
