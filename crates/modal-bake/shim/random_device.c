/*
 * A fixed-sequence std::random_device for the fTetWild child process (loaded by the
 * `modal-bake` fTetWild backend with RTLD_GLOBAL before pytetwild, or as LD_PRELOAD for
 * FloatTetwild_bin). fTetWild seeds the shuffle of its triangle insertion order from
 * std::random_device (TriangleInsertion.cpp), which makes its meshes differ run to run; with
 * these definitions interposed on libstdc++'s, every run draws the same numbers (SplitMix64
 * from a fixed state), so one input gives one mesh. Both the old and the C++11 string ABI
 * spellings of `_M_init` are defined. Built by build.rs (Linux only).
 */
static unsigned long long state = 0x9E3779B97F4A7C15ull;

void _ZNSt13random_device7_M_initERKSs(void *self, const void *token) {
    (void)self;
    (void)token;
}

void _ZNSt13random_device7_M_initERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEE(
    void *self, const void *token) {
    (void)self;
    (void)token;
}

void _ZNSt13random_device7_M_finiEv(void *self) { (void)self; }

unsigned int _ZNSt13random_device9_M_getvalEv(void *self) {
    (void)self;
    unsigned long long z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return (unsigned int)(z ^ (z >> 31));
}
