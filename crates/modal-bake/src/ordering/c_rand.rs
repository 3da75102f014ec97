//! The C library's `rand` and `srand` as glibc computes them, for METIS.
//!
//! METIS's nested dissection (`metis.rs`) draws its random numbers from the C library's
//! `rand`, reseeded with `srand(4321)` on every call; glibc, MinGW's msvcrt and macOS's libc
//! each compute a different sequence, so the same mesh got another fill-reducing order on each
//! platform, and with it another stored `surface_order` and, where the eigensolver's order is
//! METIS's, eigenvalues and modes differing at rounding level (1e-12 relative on a 50k-dof
//! mesh). The programs that link this library (`modal-bake`, `dcr-lab`, `dcr-scenes`, and this
//! crate's unit tests) define the two C symbols themselves with this generator
//! ([`c_rand_symbols!`](crate::c_rand_symbols)), so the static METIS they link draws the same
//! numbers on every platform, and they are glibc's: on Linux the bases are bit for bit what
//! they were with glibc's `rand`.
//! (Building METIS with its own generator, `USE_GKRAND`, would do as well but `metis-sys`
//! offers no way to set it.)
//!
//! The generator is glibc's `random_r` `TYPE_3` (its default for `rand`): an additive
//! lagged Fibonacci generator r(i) = r(i−3) + r(i−31) mod 2³² over 31 words, returning
//! r(i) >> 1; `srand(s)` fills the words with the Lehmer sequence w(k) = 16807·w(k−1) mod
//! (2³¹ − 1) from w(0) = s (1 for s = 0) and discards the first 310 outputs. A generator
//! never seeded is seeded with 1, as C requires.

use std::sync::Mutex;

/// Words of state (glibc's `rand_deg` for `TYPE_3`).
const DEG: usize = 31;
/// Distance between the two taps (glibc's `rand_sep` for `TYPE_3`).
const SEP: usize = 3;

/// glibc's `TYPE_3` generator state.
#[derive(Clone, Debug)]
pub struct GlibcRand {
    state: [i32; DEG],
    front: usize,
    rear: usize,
}

impl GlibcRand {
    /// The generator after `srand(seed)`.
    pub fn new(seed: u32) -> Self {
        let seed = if seed == 0 { 1 } else { seed };
        let mut state = [0i32; DEG];
        state[0] = seed as i32;
        // As glibc: Schrage's method for 16807·w mod (2³¹ − 1) on a signed 32-bit word (a seed
        // of 2³¹ or more starts negative), the product taken in 64 bits and truncated back.
        let mut word = seed as i32;
        for s in state.iter_mut().skip(1) {
            let (hi, lo) = (i64::from(word / 127_773), i64::from(word % 127_773));
            word = (16_807 * lo - 2_836 * hi) as i32;
            if word < 0 {
                word += 2_147_483_647;
            }
            *s = word;
        }
        let mut g = GlibcRand {
            state,
            front: SEP,
            rear: 0,
        };
        for _ in 0..10 * DEG {
            g.next_rand();
        }
        g
    }

    /// The next `rand()`: a value in 0..=2³¹ − 1.
    pub fn next_rand(&mut self) -> i32 {
        let val = (self.state[self.front] as u32).wrapping_add(self.state[self.rear] as u32);
        self.state[self.front] = val as i32;
        self.front += 1;
        self.rear += 1;
        if self.front >= DEG {
            self.front = 0;
        } else if self.rear >= DEG {
            self.rear = 0;
        }
        (val >> 1) as i32
    }
}

/// Held by every user of the C library's `rand` in this crate (METIS calls, which reseed it
/// and then draw a sequence that must not interleave with another's).
pub(crate) static C_RAND_USERS: Mutex<()> = Mutex::new(());

/// The process's generator behind [`rand`] and [`srand`] (`None` until first used).
static GENERATOR: Mutex<Option<GlibcRand>> = Mutex::new(None);

/// C's `srand`: reseeds the process's generator.
pub fn srand(seed: u32) {
    let mut g = GENERATOR.lock().unwrap_or_else(|e| e.into_inner());
    *g = Some(GlibcRand::new(seed));
}

/// C's `rand`: the next value of the process's generator (seeded with 1 if never seeded).
pub fn rand() -> i32 {
    let mut g = GENERATOR.lock().unwrap_or_else(|e| e.into_inner());
    g.get_or_insert_with(|| GlibcRand::new(1)).next_rand()
}

/// Defines C's `rand` and `srand` as [`rand`] and [`srand`] (`#[unsafe(no_mangle)]`), for the
/// static METIS a program links: invoke it once, at the top level of the program's own crate
/// (its `main.rs`). The program's own object is read by the linker before METIS's archive and
/// the C library, so METIS's references bind to these; a library's object would not be (it
/// is read only for symbols already wanted when the linker reaches it).
#[macro_export]
macro_rules! c_rand_symbols {
    () => {
        /// C's `rand`, for METIS: [`modal_bake::ordering::c_rand::rand`].
        #[allow(unsafe_code)]
        #[unsafe(no_mangle)]
        pub extern "C" fn rand() -> ::std::ffi::c_int {
            $crate::ordering::c_rand::rand()
        }

        /// C's `srand`, for METIS: [`modal_bake::ordering::c_rand::srand`].
        #[allow(unsafe_code)]
        #[unsafe(no_mangle)]
        pub extern "C" fn srand(seed: ::std::ffi::c_uint) {
            $crate::ordering::c_rand::srand(seed)
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    // Equality with glibc's own `rand` is tests/c_rand.rs: this test program defines `rand`
    // itself (lib.rs), so the C library's is not reachable here.

    /// glibc's own sequence for `srand(1)` (the C standard's unseeded `rand`), as printed by
    /// `for (i = 0; i < 5; i++) printf("%d\n", rand());` with glibc 2.36.
    #[test]
    fn seed_one_gives_glibcs_documented_sequence() {
        let mut g = GlibcRand::new(1);
        let got: Vec<i32> = (0..5).map(|_| g.next_rand()).collect();
        assert_eq!(
            got,
            [
                1_804_289_383,
                846_930_886,
                1_681_692_777,
                1_714_636_915,
                1_957_747_793
            ]
        );
        // srand(0) is srand(1).
        let mut z = GlibcRand::new(0);
        assert_eq!(z.next_rand(), 1_804_289_383);
    }
}
