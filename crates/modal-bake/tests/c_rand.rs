//! `modal_bake::ordering::c_rand` equals the C library's `rand` where that is glibc's. A test
//! program of its own: the library's unit tests define `rand` themselves, and no other test
//! here may draw from the C library's generator meanwhile (METIS reseeds it).

/// Over METIS's seed and seeds that exercise the unsigned-to-signed edges, 2,000 draws each.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[test]
fn equals_glibc_rand() {
    use modal_bake::ordering::c_rand::GlibcRand;
    for seed in [
        4321u32,
        1,
        0,
        2,
        12_345,
        127_773,
        2_147_483_647,
        2_147_483_648,
        u32::MAX,
    ] {
        let mut g = GlibcRand::new(seed);
        // SAFETY: srand/rand touch only libc's own generator state, which nothing else in this
        // test program uses.
        #[allow(unsafe_code)]
        let theirs: Vec<i32> = unsafe {
            libc::srand(seed);
            (0..2000).map(|_| libc::rand()).collect()
        };
        let ours: Vec<i32> = (0..2000).map(|_| g.next_rand()).collect();
        assert_eq!(ours, theirs, "seed {seed}");
    }
}
