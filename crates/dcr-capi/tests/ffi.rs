//! The `extern "C"` functions called from Rust (through the rlib): the C path gives
//! bit-identical results to the Rust API, a too-small buffer changes no state, panics become a
//! status, last errors are per thread, a model serves several threads at once, and the launch
//! codes reach the runtime.

#![allow(unsafe_code)]

use std::ffi::CStr;
use std::path::Path;
use std::sync::Arc;

use dcr_capi::*;
use dcr_runtime::response::{AttenuationParams, DistanceKind, Impact, RestingContact, ServedBy};
use dcr_runtime::testing::{plate_base, SplitMix64};
use dcr_runtime::{DistantResponse, Method, ModalModel, ResponseParams};

/// Loads `base` written to `dir` through the C API.
fn c_model(dir: &Path) -> *mut DcrModel {
    let path = dir.join("plate.modes");
    plate_base().write_atomic(&path).unwrap();
    let c = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    let mut m = std::ptr::null_mut();
    // SAFETY: valid C string and out pointer.
    assert_eq!(unsafe { dcr_model_load(c.as_ptr(), &mut m) }, DcrStatus::Ok);
    assert!(!m.is_null());
    m
}

fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated, valid until the next failing call on this thread.
    unsafe { CStr::from_ptr(dcr_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// Random impacts and resting contacts on the plate (z = 0, 1 m × 0.6 m), object frame.
fn scene(seed: u64, steps: usize) -> (Vec<Vec<Impact>>, Vec<RestingContact>) {
    let mut rng = SplitMix64(seed);
    let resting = (0..17)
        .map(|i| RestingContact {
            id: 100 + i,
            point: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.001],
        })
        .collect();
    let impacts = (0..steps)
        .map(|s| {
            (0..s % 3)
                .map(|_| Impact {
                    point: [rng.range(0.0, 1.0), rng.range(0.0, 0.6), 0.0],
                    direction: [0.0, 0.0, -1.0],
                    impulse: rng.range(0.0, 3.0),
                })
                .collect()
        })
        .collect();
    (impacts, resting)
}

fn c_impacts(v: &[Impact]) -> Vec<DcrImpact> {
    v.iter()
        .map(|i| DcrImpact {
            point: i.point,
            direction: i.direction,
            impulse: i.impulse,
        })
        .collect()
}

fn c_resting(v: &[RestingContact]) -> Vec<DcrRestingContact> {
    v.iter()
        .map(|c| DcrRestingContact {
            id: c.id,
            point: c.point,
        })
        .collect()
}

/// `dcr_response_step` over slices, offering the first `capacity` entries of `out`: (status,
/// required count). `r` must be a live handle.
fn step(
    r: *mut DcrResponse,
    impacts: &[DcrImpact],
    resting: &[DcrRestingContact],
    out: &mut [DcrContactResponse],
    capacity: usize,
) -> (DcrStatus, usize) {
    assert!(capacity <= out.len());
    let mut n = 0;
    // SAFETY: slices with their lengths; `r` is live (caller contract).
    let st = unsafe {
        dcr_response_step(
            r,
            impacts.as_ptr(),
            impacts.len(),
            resting.as_ptr(),
            resting.len(),
            out.as_mut_ptr(),
            capacity,
            &mut n,
        )
    };
    (st, n)
}

/// For each method, `dcr_response_step` returns exactly (bit for bit) what
/// `DistantResponse::step` returns on the same base, parameters and inputs, over steps with
/// zero, one and two impacts and carried-over filter state.
#[test]
fn c_response_step_equals_the_rust_step_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let cm = c_model(dir.path());
    let model = Arc::new(ModalModel::from_base(plate_base()).unwrap());
    let (impacts, resting) = scene(3, 12);
    for (method, carry, distance) in [
        (DCR_METHOD_MODAL, false, DistanceKind::Heat),
        (DCR_METHOD_MODAL, true, DistanceKind::Heat),
        (DCR_METHOD_ATTENUATION, false, DistanceKind::Heat),
        (DCR_METHOD_ATTENUATION, false, DistanceKind::HeatTable),
        (DCR_METHOD_ATTENUATION, false, DistanceKind::Euclidean),
        (DCR_METHOD_TRANSFER, false, DistanceKind::Heat),
    ] {
        let mut p = DcrResponseParams::defaults();
        p.method = method;
        p.carry_over = carry;
        p.lateral_kick = !carry;
        p.attenuation.distance = match distance {
            DistanceKind::Heat => DCR_DISTANCE_HEAT,
            DistanceKind::HeatTable => DCR_DISTANCE_HEAT_TABLE,
            _ => DCR_DISTANCE_EUCLIDEAN,
        };
        let mut cr = std::ptr::null_mut();
        // SAFETY: live model, valid params and out pointer.
        assert_eq!(
            unsafe { dcr_response_create(cm, &p, &mut cr) },
            DcrStatus::Ok,
            "{}",
            last_error()
        );
        let rp = ResponseParams {
            method: match method {
                DCR_METHOD_MODAL => Method::Modal,
                DCR_METHOD_TRANSFER => Method::Transfer,
                _ => Method::Attenuation(AttenuationParams {
                    distance,
                    ..Default::default()
                }),
            },
            carry_over: carry,
            lateral_kick: !carry,
            ..Default::default()
        };
        let mut rust = DistantResponse::new(Arc::clone(&model), rp).unwrap();
        let cres = c_resting(&resting);
        let mut out = vec![DcrContactResponse::default(); resting.len()];
        for (s, imp) in impacts.iter().enumerate() {
            let cap = out.len();
            let (st, n) = step(cr, &c_impacts(imp), &cres, &mut out, cap);
            assert_eq!(st, DcrStatus::Ok, "{}", last_error());
            assert_eq!(n, resting.len());
            let want = rust.step(imp, &resting);
            for (c, r) in out.iter().zip(want) {
                let tag = format!(
                    "method {method} carry {carry} {distance:?} step {s} contact {}",
                    r.id
                );
                assert_eq!(c.id, r.id, "{tag}");
                assert_eq!(c.delta_v.to_bits(), r.delta_v.to_bits(), "{tag}");
                assert_eq!(
                    c.peak_displacement.to_bits(),
                    r.peak_displacement.to_bits(),
                    "{tag}"
                );
                assert_eq!(c.normal, r.normal, "{tag}");
                assert_eq!(c.point, r.point, "{tag}");
                assert_eq!(c.lateral_delta_v, r.lateral_delta_v, "{tag}");
                assert_eq!(c.mapped, r.mapped, "{tag}");
                let served = match r.served_by {
                    ServedBy::Modal => DCR_SERVED_BY_MODAL,
                    ServedBy::Attenuation => DCR_SERVED_BY_ATTENUATION,
                    ServedBy::TransferTable => DCR_SERVED_BY_TRANSFER_TABLE,
                    ServedBy::Unmapped => DCR_SERVED_BY_UNMAPPED,
                };
                assert_eq!(c.served_by, served, "{tag}");
            }
            let mut info = DcrStepInfo::default();
            // SAFETY: live handle, valid out pointer.
            assert_eq!(
                unsafe { dcr_response_step_info(cr, &mut info) },
                DcrStatus::Ok
            );
            let ri = rust.last_step_info();
            assert_eq!(info.impacts_applied, ri.impacts_applied);
            assert_eq!(info.contacts_mapped_now, ri.contacts_mapped_now);
            if s > 0 && imp.iter().any(|i| i.impulse >= 1e-3) && !carry {
                assert!(out.iter().any(|c| c.delta_v > 0.0), "step {s}: no response");
            }
        }
        // SAFETY: live handle, freed once.
        unsafe { dcr_response_free(cr) };
    }
    // SAFETY: live handle, freed once.
    unsafe { dcr_model_free(cm) };
}

/// `DCR_STATUS_BUFFER_TOO_SMALL` leaves the response untouched: with carried-over filter
/// state, a response that first got a too-small buffer then answers exactly as a response that
/// never saw that call.
#[test]
fn a_too_small_buffer_changes_no_state() {
    let dir = tempfile::tempdir().unwrap();
    let cm = c_model(dir.path());
    let (impacts, resting) = scene(9, 6);
    let mut p = DcrResponseParams::defaults();
    p.method = DCR_METHOD_MODAL;
    p.carry_over = true;
    let (mut a, mut b) = (std::ptr::null_mut(), std::ptr::null_mut());
    // SAFETY: live model, valid params and out pointers.
    unsafe {
        assert_eq!(dcr_response_create(cm, &p, &mut a), DcrStatus::Ok);
        assert_eq!(dcr_response_create(cm, &p, &mut b), DcrStatus::Ok);
    }
    let cres = c_resting(&resting);
    let mut out_a = vec![DcrContactResponse::default(); resting.len()];
    let mut out_b = out_a.clone();
    for imp in &impacts {
        let ci = c_impacts(imp);
        // Capacity 3 < resting.len(): refused, nothing runs.
        assert_eq!(
            step(a, &ci, &cres, &mut out_a, 3),
            (DcrStatus::BufferTooSmall, resting.len())
        );
        for (r, o) in [(a, &mut out_a), (b, &mut out_b)] {
            let cap = o.len();
            assert_eq!(step(r, &ci, &cres, o, cap).0, DcrStatus::Ok);
        }
        assert_eq!(out_a, out_b);
    }
    assert!(out_a.iter().any(|c| c.delta_v > 0.0));
    // SAFETY: live handles, each freed once.
    unsafe {
        dcr_response_free(a);
        dcr_response_free(b);
        dcr_model_free(cm);
    }
}

/// A panic inside a guarded entry point becomes `DCR_STATUS_PANIC` with the panic's message
/// as the thread's last error; nothing unwinds past the guard.
#[test]
fn a_panic_becomes_a_status_and_a_message() {
    let st = guard("dcr_test_entry", || panic!("boom at the boundary"));
    assert_eq!(st, DcrStatus::Panic);
    let msg = last_error();
    assert!(
        msg.starts_with("dcr_test_entry: internal error (panic: boom at the boundary)"),
        "{msg}"
    );
    let st = guard("dcr_test_entry", || Err(Failure::invalid("x")));
    assert_eq!(st, DcrStatus::InvalidArgument);
}

/// The last error belongs to the thread that failed: another thread's failure does not
/// replace it, and a thread that never failed reads an empty message.
#[test]
fn last_errors_are_per_thread() {
    let dir = tempfile::tempdir().unwrap();
    let missing = std::ffi::CString::new(
        dir.path()
            .join("main-thread.modes")
            .to_str()
            .unwrap()
            .to_string(),
    )
    .unwrap();
    let mut m = std::ptr::null_mut();
    // SAFETY: valid C string and out pointer.
    assert_eq!(
        unsafe { dcr_model_load(missing.as_ptr(), &mut m) },
        DcrStatus::Io
    );
    let other = std::thread::spawn(|| {
        let before = last_error();
        let mut m = std::ptr::null_mut();
        // SAFETY: NULL path is checked; valid out pointer.
        let st = unsafe { dcr_model_load(std::ptr::null(), &mut m) };
        (before, st, last_error())
    })
    .join()
    .unwrap();
    assert_eq!(other.0, "");
    assert_eq!(other.1, DcrStatus::NullPointer);
    assert!(other.2.contains("`path` is NULL"));
    let mine = last_error();
    assert!(mine.contains("main-thread.modes"), "{mine}");
}

/// A `DcrModel` handle is shared by threads that each own a response: answers equal the
/// single-thread ones.
#[test]
fn one_model_serves_several_threads() {
    struct Shared(*mut DcrModel);
    // SAFETY: the model is immutable (`ModalModel: Send + Sync`) and outlives the threads.
    unsafe impl Sync for Shared {}
    let dir = tempfile::tempdir().unwrap();
    let shared = Shared(c_model(dir.path()));
    let (impacts, resting) = scene(5, 8);
    let run = |shared: &Shared| {
        let mut p = DcrResponseParams::defaults();
        p.method = DCR_METHOD_MODAL;
        let mut r = std::ptr::null_mut();
        let mut all = Vec::new();
        // SAFETY: live model; arrays with the counts given; live handle freed once.
        unsafe {
            assert_eq!(dcr_response_create(shared.0, &p, &mut r), DcrStatus::Ok);
            let cres = c_resting(&resting);
            let mut out = vec![DcrContactResponse::default(); cres.len()];
            for imp in &impacts {
                let cap = out.len();
                assert_eq!(
                    step(r, &c_impacts(imp), &cres, &mut out, cap).0,
                    DcrStatus::Ok
                );
                all.extend(out.iter().map(|c| c.delta_v.to_bits()));
            }
            dcr_response_free(r);
        }
        all
    };
    let alone = run(&shared);
    let together: Vec<Vec<u64>> = std::thread::scope(|s| {
        let hs: Vec<_> = (0..3).map(|_| s.spawn(|| run(&shared))).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for t in together {
        assert_eq!(t, alone);
    }
    // SAFETY: live handle, freed once.
    unsafe { dcr_model_free(shared.0) };
}

/// `dcr_version` reports this crate's version and the header's ABI revision, and the static
/// version string agrees.
#[test]
fn version_matches_the_crate() {
    let mut v = DcrVersion::default();
    // SAFETY: valid out pointer.
    assert_eq!(unsafe { dcr_version(&mut v) }, DcrStatus::Ok);
    assert_eq!(
        format!("{}.{}.{}", v.major, v.minor, v.patch),
        env!("CARGO_PKG_VERSION")
    );
    assert_eq!(v.abi, DCR_ABI_VERSION);
    // SAFETY: static NUL-terminated string.
    let s = unsafe { CStr::from_ptr(dcr_version_string()) };
    assert_eq!(s.to_str().unwrap(), env!("CARGO_PKG_VERSION"));
}

/// On this toolchain the per-step C structs share the runtime types' layouts, so
/// `dcr_response_step` passes impacts and resting contacts without a copy and returns the
/// responses as whole-struct copies (the C call then costs what the Rust call costs; see
/// docs/benchmarks.md). A failure here is a slowdown, not a wrong result: reorder the C
/// struct's fields to the runtime type's declared order.
#[test]
fn per_step_structs_share_the_runtime_layout() {
    assert_eq!(zero_copy_layouts(), (true, true, true));
}

/// The same for the world's per-step structs: contact reports and body states pass without a
/// copy, and `dcr_world_step` lends the runtime's own event buffer.
#[test]
fn world_step_structs_share_the_runtime_layout() {
    assert_eq!(world_zero_copy_layouts(), (true, true, true));
}

/// `DcrResponseParams.launch`: the default is the paper's rule; `DCR_LAUNCH_SUSTAINED_PEAK`
/// reaches the runtime (accepted with carry-over, refused without it, naming the field); an
/// unknown code is an invalid argument naming the field.
#[test]
fn launch_codes_reach_the_runtime() {
    let dir = tempfile::tempdir().unwrap();
    let cm = c_model(dir.path());
    assert_eq!(
        DcrResponseParams::defaults().launch,
        DCR_LAUNCH_PEAK_OVER_STEP
    );
    for (launch, carry, ok) in [
        (DCR_LAUNCH_SUSTAINED_PEAK, true, true),
        (DCR_LAUNCH_SUSTAINED_PEAK, false, false),
        (7, true, false),
    ] {
        let mut p = DcrResponseParams::defaults();
        p.method = DCR_METHOD_MODAL;
        p.carry_over = carry;
        p.launch = launch;
        let mut cr = std::ptr::null_mut();
        // SAFETY: live model, valid params and out pointer.
        let st = unsafe { dcr_response_create(cm, &p, &mut cr) };
        if ok {
            assert_eq!(st, DcrStatus::Ok, "{}", last_error());
            // SAFETY: live handle, freed once.
            unsafe { dcr_response_free(cr) };
        } else {
            assert_ne!(st, DcrStatus::Ok);
            assert!(last_error().contains("launch"), "{}", last_error());
        }
    }
    // SAFETY: live handle, freed once.
    unsafe { dcr_model_free(cm) };
}
