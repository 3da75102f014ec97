//! `modal-bake`: bake, inspect and check `.modes` bases. See `modal-bake --help`.
//!
//! Also defines the C library's `rand` and `srand` for the METIS this program links statically
//! (`modal_bake::ordering::c_rand`: glibc's generator, so a mesh gets the same fill-reducing
//! orders, and so the same base, on every platform). They are defined here, in the program's
//! own object, which the linker reads before METIS's archive and the C library: METIS's
//! references bind to them.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}

/// C's `rand`, for METIS: [`modal_bake::ordering::c_rand::rand`].
#[allow(unsafe_code)]
#[unsafe(no_mangle)]
pub extern "C" fn rand() -> std::ffi::c_int {
    modal_bake::ordering::c_rand::rand()
}

/// C's `srand`, for METIS: [`modal_bake::ordering::c_rand::srand`].
#[allow(unsafe_code)]
#[unsafe(no_mangle)]
pub extern "C" fn srand(seed: std::ffi::c_uint) {
    modal_bake::ordering::c_rand::srand(seed)
}
