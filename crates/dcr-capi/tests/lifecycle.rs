//! The C ABI's object lifecycle and argument ranges, called from Rust through the rlib.
//!
//! Expectations: a removed object's handle is `DCR_STATUS_INVALID_HANDLE` for every call, also
//! after its slot is reused by a new object (next generation); enable, gain and threshold
//! setters refuse bad values with a message; an oversampling factor below 1, a NaN or 1e308
//! pose translation, a NaN inverse inertia and `dcr_response_impulse(NaN, inf, …)` are
//! `DCR_STATUS_INVALID_ARGUMENT` with a message naming the argument.

#![allow(unsafe_code)]

use std::ffi::CStr;

use dcr_capi::*;
use dcr_runtime::testing::plate_base;

fn last_error() -> String {
    // SAFETY: never NULL, NUL-terminated.
    unsafe { CStr::from_ptr(dcr_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn model() -> *mut DcrModel {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("plate.modes");
    plate_base().write_atomic(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let mut m = std::ptr::null_mut();
    // SAFETY: valid buffer and out pointer.
    assert_eq!(
        unsafe { dcr_model_load_bytes(bytes.as_ptr(), bytes.len(), &mut m) },
        DcrStatus::Ok
    );
    m
}

#[test]
fn removed_handles_are_stale_and_setters_check_values() {
    let m = model();
    let mut wp = DcrWorldParams::defaults();
    wp.gravity = [0.0; 3];
    let mut w = std::ptr::null_mut();
    // SAFETY: valid pointers throughout; handles freed once at the end.
    unsafe {
        assert_eq!(dcr_world_create(&wp, &mut w), DcrStatus::Ok);
        let mut desc = DcrElasticObjectDesc::defaults();
        desc.model = m;
        desc.body = 1;
        let mut a = 0;
        assert_eq!(dcr_world_add_object(w, &desc, &mut a), DcrStatus::Ok);
        assert_eq!(a, 0);
        assert_eq!(
            dcr_world_set_object_gain(w, a, -1.0),
            DcrStatus::InvalidArgument
        );
        assert!(last_error().contains("gain"), "{}", last_error());
        assert_eq!(
            dcr_world_set_object_threshold(w, a, f64::NAN),
            DcrStatus::InvalidArgument
        );
        assert_eq!(dcr_world_set_object_gain(w, a, 2.0), DcrStatus::Ok);
        assert_eq!(dcr_world_set_object_enabled(w, a, false), DcrStatus::Ok);
        assert_eq!(dcr_world_remove_object(w, a), DcrStatus::Ok);
        assert_eq!(dcr_world_remove_object(w, a), DcrStatus::InvalidHandle);
        assert!(last_error().contains("removed"), "{}", last_error());
        let mut b = 0;
        assert_eq!(dcr_world_add_object(w, &desc, &mut b), DcrStatus::Ok);
        assert_eq!((b & 0xffff_ffff, b >> 32), (0, 1), "slot 0, generation 1");
        for st in [
            dcr_world_set_object_gain(w, a, 1.0),
            dcr_world_set_object_enabled(w, a, true),
            dcr_world_set_object_threshold(w, a, 1.0),
            dcr_world_remove_object(w, a),
        ] {
            assert_eq!(st, DcrStatus::InvalidHandle);
        }
        let mut t = DcrObjectTotals::default();
        assert_eq!(
            dcr_world_object_totals(w, a, &mut t),
            DcrStatus::InvalidHandle
        );
        assert_eq!(dcr_world_object_totals(w, b, &mut t), DcrStatus::Ok);
        // Ranges of the pose.
        for bad in [f64::NAN, 1e308, f64::INFINITY] {
            let pose = DcrPose {
                rotation: [0.0, 0.0, 0.0, 1.0],
                translation: [0.0, bad, 0.0],
            };
            assert_eq!(dcr_world_set_pose(w, b, &pose), DcrStatus::InvalidArgument);
            assert!(last_error().contains("translation[1]"), "{}", last_error());
            desc.pose = pose;
            desc.body = 5;
            let mut c = 0;
            assert_eq!(
                dcr_world_add_object(w, &desc, &mut c),
                DcrStatus::InvalidArgument
            );
        }
        assert_eq!(dcr_world_set_h(w, 1.0 / 60.0), DcrStatus::Ok);
        let mut h = 0.0;
        assert_eq!(dcr_world_h(w, &mut h), DcrStatus::Ok);
        assert_eq!(h, 1.0 / 60.0);
        assert_eq!(dcr_world_set_h(w, -1.0), DcrStatus::InvalidArgument);
        dcr_world_free(w);
    }
    // SAFETY: freed once.
    unsafe { dcr_model_free(m) };
}

#[test]
fn out_of_range_arguments_are_refused_with_a_message() {
    let m = model();
    // SAFETY: valid pointers throughout.
    unsafe {
        for k in [0.5, 0.01, 1e-300, f64::NAN] {
            let mut p = DcrResponseParams::defaults();
            p.sampling = DCR_SAMPLING_OVERSAMPLE;
            p.sampling_value = k;
            let mut r = std::ptr::null_mut();
            assert_eq!(
                dcr_response_create(m, &p, &mut r),
                DcrStatus::InvalidArgument,
                "K = {k}"
            );
            assert!(last_error().contains("oversampling"), "{}", last_error());
            assert!(r.is_null());
        }
        let mut inertia = [0.0; 9];
        inertia[4] = f64::NAN;
        let (r, n) = ([0.1, 0.0, 0.0], [0.0, 0.0, 1.0]);
        let mut out = 0.0;
        assert_eq!(
            dcr_effective_mass(1.0, inertia.as_ptr(), r.as_ptr(), n.as_ptr(), &mut out),
            DcrStatus::InvalidArgument
        );
        assert!(last_error().contains("inv_inertia[4]"), "{}", last_error());
        let mut j = [0.0; 3];
        assert_eq!(
            dcr_response_impulse(f64::NAN, f64::INFINITY, n.as_ptr(), j.as_mut_ptr()),
            DcrStatus::InvalidArgument
        );
        assert!(last_error().contains("m_eff"), "{}", last_error());
        assert_eq!(
            dcr_response_impulse(1.0, f64::INFINITY, n.as_ptr(), j.as_mut_ptr()),
            DcrStatus::InvalidArgument
        );
        assert!(last_error().contains("delta_v"), "{}", last_error());
        assert_eq!(
            dcr_response_impulse(2.0, 0.5, n.as_ptr(), j.as_mut_ptr()),
            DcrStatus::Ok
        );
        assert_eq!(j, [0.0, 0.0, 1.0]);
        dcr_model_free(m);
    }
}
