//! The C ABI called from Rust through the rlib: the same bytes and report as the library
//! on every fixture × both machines, joints from CL points, joint-array patching, and the
//! refusals (status and message, never a crash).

use polepatch::kinematics::{BranchRule, Machine, forward, inverse_path};
use polepatch::patcher::{Path, patch_path};
use polepatch_capi::*;
use std::ffi::{CStr, CString};
use std::path::PathBuf;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn fixtures() -> Vec<PathBuf> {
    polepatch_fixturegen::nc_files(&root().join("fixtures"))
}

fn last_error() -> String {
    unsafe { CStr::from_ptr(pp_last_error()) }
        .to_string_lossy()
        .into_owned()
}

fn machine(name: &str) -> *mut PpMachine {
    let name = CString::new(name).unwrap();
    let mut m = std::ptr::null_mut();
    assert_eq!(
        unsafe { pp_machine_builtin(name.as_ptr(), &mut m) },
        PpStatus::PpOk
    );
    m
}

fn without_timing(json: &[u8]) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
    for z in v["zones"].as_array_mut().unwrap() {
        z.as_object_mut().unwrap().remove("solve_time_ms");
    }
    v
}

fn take(b: &mut PpBuffer) -> Vec<u8> {
    let v = if b.data.is_null() {
        Vec::new()
    } else {
        unsafe { std::slice::from_raw_parts(b.data, b.len) }.to_vec()
    };
    unsafe { pp_buffer_free(b) };
    assert!(b.data.is_null() && b.len == 0);
    v
}

/// Every fixture, on the two machines in turn (each machine sees half the fixtures, every
/// dialect and kind on both).
#[test]
fn patch_nc_through_the_abi_is_the_library_on_every_fixture() {
    let mut n = 0;
    for (turn, name) in ["mikron-ucp710", "mikron-hsm600"].into_iter().enumerate() {
        let m = machine(name);
        let rust_machine = Machine::builtin(name).unwrap();
        for path in fixtures().into_iter().skip(turn).step_by(2) {
            let bytes = std::fs::read(&path).unwrap();
            let label = path.display().to_string();
            let c_label = CString::new(label.clone()).unwrap();
            let mut opts = pp_options_default();
            opts.name = c_label.as_ptr();
            let (mut out, mut report) = (
                PpBuffer {
                    data: std::ptr::null_mut(),
                    len: 0,
                },
                PpBuffer {
                    data: std::ptr::null_mut(),
                    len: 0,
                },
            );
            let status = unsafe {
                pp_patch_nc(m, bytes.as_ptr(), bytes.len(), &opts, &mut out, &mut report)
            };
            let lib_opts = polepatch::PatchOptions::named(label.clone());
            match polepatch::patch_nc(&bytes, &rust_machine, &lib_opts) {
                Ok((want, want_report)) => {
                    assert_eq!(status, PpStatus::PpOk, "{label}: {}", last_error());
                    assert_eq!(take(&mut out), want, "{label} on {name}");
                    let want_json = serde_json::to_vec_pretty(&want_report).unwrap();
                    assert_eq!(
                        without_timing(&take(&mut report)),
                        without_timing(&want_json)
                    );
                }
                Err(e) => {
                    assert_eq!(status, PpStatus::PpBadInput, "{label}");
                    assert_eq!(last_error(), e.to_string());
                }
            }
            n += 1;
        }
        unsafe { pp_machine_free(m) };
    }
    assert!(n >= 100, "{n}");
}

#[test]
fn cl_to_joints_inverts_forward_kinematics() {
    let m = machine("mikron-ucp710");
    let rust_machine = Machine::builtin("mikron-ucp710").unwrap();
    let joints_in = [(14.825, 137.259), (1.0, 180.0), (0.5, -170.0), (-3.0, 12.0)];
    let mut cl = Vec::new();
    for (k, &(p, c)) in joints_in.iter().enumerate() {
        let o = forward(&rust_machine, p, c);
        // Not normalised on purpose: the ABI normalises.
        cl.extend_from_slice(&[k as f64, 0.0, -8.0, 2.0 * o[0], 2.0 * o[1], 2.0 * o[2]]);
    }
    let mut out = vec![0.0; 5 * joints_in.len()];
    let status = unsafe {
        pp_cl_to_joints(
            m,
            cl.as_ptr(),
            joints_in.len(),
            PpBranchRule::PpBranchNearest as i32,
            out.as_mut_ptr(),
        )
    };
    assert_eq!(status, PpStatus::PpOk, "{}", last_error());
    let axes: Vec<[f64; 3]> = joints_in
        .iter()
        .map(|&(p, c)| forward(&rust_machine, p, c))
        .collect();
    let want = inverse_path(&rust_machine, &axes, BranchRule::Nearest);
    for (k, w) in want.iter().enumerate() {
        assert_eq!(&out[5 * k..5 * k + 3], &cl[6 * k..6 * k + 3]);
        assert!((out[5 * k + 3] - w.p_deg).abs() < 1e-9 && (out[5 * k + 4] - w.c_deg).abs() < 1e-9);
        let o = forward(&rust_machine, out[5 * k + 3], out[5 * k + 4]);
        assert!((0..3).all(|i| (o[i] - axes[k][i]).abs() < 1e-12));
    }
    unsafe { pp_machine_free(m) };
}

/// Issue 19 §5: (1e300, 0, 1e300) gave PP_OK with NaN joints (the squares overflowed).
/// Huge axes are normalised; an axis shorter than 1e-9 is "zero" (bad input), and nothing
/// is written then.
#[test]
fn cl_to_joints_normalises_huge_axes() {
    let m = machine("mikron-ucp710");
    let rust_machine = Machine::builtin("mikron-ucp710").unwrap();
    for scale in [1e300, f64::MAX, 1e5, 1.0] {
        let cl = [1.0, 2.0, 3.0, scale, 0.0, scale];
        let mut out = [f64::NAN; 5];
        let status = unsafe {
            pp_cl_to_joints(
                m,
                cl.as_ptr(),
                1,
                PpBranchRule::PpBranchPositive as i32,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(status, PpStatus::PpOk, "{scale}: {}", last_error());
        assert!(out.iter().all(|v| v.is_finite()), "{scale}: {out:?}");
        assert!((out[3] - 45.0).abs() < 1e-9, "{scale}: {out:?}");
        let o = forward(&rust_machine, out[3], out[4]);
        let h = 0.5f64.sqrt();
        assert!((o[0] - h).abs() < 1e-12 && o[1].abs() < 1e-12 && (o[2] - h).abs() < 1e-12);
    }
    for scale in [0.0, 1e-300, 1e-10] {
        let cl = [1.0, 2.0, 3.0, scale, 0.0, scale];
        let mut out = [7.0; 5];
        let status = unsafe {
            pp_cl_to_joints(
                m,
                cl.as_ptr(),
                1,
                PpBranchRule::PpBranchNearest as i32,
                out.as_mut_ptr(),
            )
        };
        assert_eq!(status, PpStatus::PpBadInput, "{scale}");
        assert!(last_error().contains("zero"), "{}", last_error());
        assert_eq!(out, [7.0; 5], "nothing written");
    }
    unsafe { pp_machine_free(m) };
}

/// Issue 26 item 4: a tool axis pointing down needs A = 180° on the UCP710, whose A ends at
/// 120°: `PP_OUT_OF_RANGE` naming the point, the value and the range (it was `PP_OK`), and
/// nothing written. The same axis on a machine whose range holds it is `PP_OK`.
#[test]
fn cl_to_joints_refuses_a_primary_angle_outside_the_range() {
    let m = machine("mikron-ucp710");
    let cl = [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0];
    let mut out = [7.0; 10];
    for rule in [
        PpBranchRule::PpBranchNearest,
        PpBranchRule::PpBranchPositive,
    ] {
        let status = unsafe { pp_cl_to_joints(m, cl.as_ptr(), 2, rule as i32, out.as_mut_ptr()) };
        assert_eq!(status, PpStatus::PpOutOfRange, "{rule:?}: {}", last_error());
        let e = last_error();
        assert!(
            e.contains("point 1") && e.contains("180") && e.contains("120"),
            "{e}"
        );
        assert_eq!(out, [7.0; 10], "nothing written");
    }
    unsafe { pp_machine_free(m) };
    let toml =
        std::fs::read_to_string(root().join("crates/kinematics/machines/mikron-ucp710.toml"))
            .unwrap()
            .replace("range_deg = [-100.0, 120.0]", "range_deg = [-100.0, 180.0]");
    let text = std::ffi::CString::new(toml).unwrap();
    let mut wide: *mut PpMachine = std::ptr::null_mut();
    assert_eq!(
        unsafe { pp_machine_from_toml(text.as_ptr(), &mut wide) },
        PpStatus::PpOk,
        "{}",
        last_error()
    );
    let status = unsafe {
        pp_cl_to_joints(
            wide,
            cl.as_ptr(),
            2,
            PpBranchRule::PpBranchPositive as i32,
            out.as_mut_ptr(),
        )
    };
    assert_eq!(status, PpStatus::PpOk, "{}", last_error());
    assert!((out[8] - 180.0).abs() < 1e-9, "{out:?}");
    unsafe { pp_machine_free(wide) };
}

#[test]
fn patch_joints_is_the_patcher_on_the_arrays() {
    // SING's long TCPM run, as a CAM plugin would hold it.
    let rust_machine = Machine::builtin("mikron-ucp710").unwrap();
    let lp = polepatch::load_nc(
        &std::fs::read(root().join("fixtures/c17/SING.I")).unwrap(),
        "SING.I",
        &rust_machine,
        None,
    )
    .unwrap();
    let path = lp.runs[0].path.as_ref().unwrap();
    let flat: Vec<f64> = path.axes.iter().flatten().copied().collect();
    let n = path.axes.len();
    let m = machine("mikron-ucp710");
    let mut out = vec![0.0; 5 * n];
    let mut zones = [PpZone {
        first: 0,
        last: 0,
        outcome: PpOutcome::PpUnchanged,
        c_ratio_before: 0.0,
        c_ratio_after: 0.0,
        overall_ratio_before: 0.0,
        overall_ratio_after: 0.0,
        max_deviation_deg: 0.0,
        points_modified: 0,
    }; 4];
    let mut count = 0usize;
    let status = unsafe {
        pp_patch_joints(
            m,
            flat.as_ptr(),
            n,
            path.feed_mm_min,
            std::ptr::null(),
            out.as_mut_ptr(),
            zones.as_mut_ptr(),
            zones.len(),
            &mut count,
        )
    };
    assert_eq!(status, PpStatus::PpOk, "{}", last_error());
    assert_eq!(count, 1);
    assert_eq!(zones[0].outcome, PpOutcome::PpReached);
    assert!(zones[0].c_ratio_before < 0.2 && zones[0].c_ratio_after >= 1.0);
    // The same as the patcher with the options the ABI documents.
    let mut popts = polepatch::patcher::PatchOptions::default();
    popts.c_decimals = popts.max_decimals;
    popts.p_decimals = popts.max_decimals;
    popts.keep_last_point = true;
    let own = Path {
        s_mm: path.s_mm.clone(),
        axes: path.axes.clone(),
        feed_mm_min: path.feed_mm_min,
    };
    let r = patch_path(&own, &rust_machine, &popts).unwrap();
    for k in 0..n {
        assert_eq!(out[5 * k + 3], r.p_deg[k]);
        assert_eq!(out[5 * k + 4], r.c_deg[k]);
    }
    assert_eq!(out[5 * (n - 1) + 4], path.axes[n - 1][4], "last point kept");
    unsafe { pp_machine_free(m) };
}

#[test]
fn refusals_give_a_status_and_a_message() {
    let m = machine("mikron-ucp710");
    let mut out = PpBuffer {
        data: std::ptr::null_mut(),
        len: 0,
    };
    let text = b"G1 X0 Y0 Z0 A1 C0 F1000\nX1 C1..5\n";
    let cases: Vec<(&str, PpStatus, PpStatus)> = vec![
        (
            "syntax",
            unsafe {
                pp_patch_nc(
                    m,
                    text.as_ptr(),
                    text.len(),
                    std::ptr::null(),
                    &mut out,
                    std::ptr::null_mut(),
                )
            },
            PpStatus::PpBadInput,
        ),
        (
            "null machine",
            unsafe {
                pp_patch_nc(
                    std::ptr::null(),
                    text.as_ptr(),
                    text.len(),
                    std::ptr::null(),
                    &mut out,
                    std::ptr::null_mut(),
                )
            },
            PpStatus::PpBadMachine,
        ),
        (
            "huge length",
            unsafe {
                pp_patch_nc(
                    m,
                    text.as_ptr(),
                    usize::MAX,
                    std::ptr::null(),
                    &mut out,
                    std::ptr::null_mut(),
                )
            },
            PpStatus::PpBadInput,
        ),
        (
            "bad toml",
            unsafe {
                let t = CString::new("[x]\nv_m_min = -1").unwrap();
                let mut mm = std::ptr::null_mut();
                pp_machine_from_toml(t.as_ptr(), &mut mm)
            },
            PpStatus::PpBadMachine,
        ),
        (
            "null out machine",
            unsafe {
                let t = CString::new("mikron-ucp710").unwrap();
                pp_machine_builtin(t.as_ptr(), std::ptr::null_mut())
            },
            PpStatus::PpBadInput,
        ),
        (
            "one point",
            unsafe {
                let mut c = 0usize;
                pp_patch_joints(
                    m,
                    [0.0; 5].as_ptr(),
                    1,
                    1000.0,
                    std::ptr::null(),
                    [0.0; 5].as_mut_ptr(),
                    std::ptr::null_mut(),
                    0,
                    &mut c,
                )
            },
            PpStatus::PpBadInput,
        ),
        (
            "standing still",
            unsafe {
                let pts = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 90.0];
                let mut o = [0.0; 10];
                let mut c = 0usize;
                pp_patch_joints(
                    m,
                    pts.as_ptr(),
                    2,
                    1000.0,
                    std::ptr::null(),
                    o.as_mut_ptr(),
                    std::ptr::null_mut(),
                    0,
                    &mut c,
                )
            },
            PpStatus::PpBadInput,
        ),
    ];
    for (what, got, want) in cases {
        assert_eq!(got, want, "{what}: {}", last_error());
        assert!(!last_error().is_empty(), "{what}: no message");
    }
    // A success clears the message.
    let mut m2 = std::ptr::null_mut();
    let t = CString::new("mikron-hsm600").unwrap();
    assert_eq!(
        unsafe { pp_machine_builtin(t.as_ptr(), &mut m2) },
        PpStatus::PpOk
    );
    assert_eq!(last_error(), "");
    unsafe {
        pp_machine_free(m2);
        pp_machine_free(m);
        pp_buffer_free(std::ptr::null_mut());
    }
}

/// `pp_simulate_nc` is `polepatch::simulate_nc`: the same report JSON on SING (A-C) and a
/// B-C program, each on its machine; a NULL output is refused with a message.
#[test]
fn simulate_nc_through_the_abi_is_the_library() {
    for (name, file) in [
        ("mikron-ucp710", "fixtures/c17/SING.I"),
        (
            "mikron-hsm600",
            "fixtures/generated/heidenhain-bc-swing-d0.1.I",
        ),
    ] {
        let bytes = std::fs::read(root().join(file)).unwrap();
        let m = machine(name);
        let mut out = PpBuffer {
            data: std::ptr::null_mut(),
            len: 0,
        };
        let status =
            unsafe { pp_simulate_nc(m, bytes.as_ptr(), bytes.len(), std::ptr::null(), &mut out) };
        assert_eq!(status, PpStatus::PpOk, "{}", last_error());
        let got: serde_json::Value = serde_json::from_slice(&take(&mut out)).unwrap();
        let lib = polepatch::simulate_nc(
            &bytes,
            &Machine::builtin(name).unwrap(),
            &polepatch::SimulateOptions::default(),
        )
        .unwrap();
        assert_eq!(got, serde_json::to_value(&lib).unwrap());
        assert!(got["total"]["time_s"].as_f64().unwrap() > 0.0);
        let status = unsafe {
            pp_simulate_nc(
                m,
                bytes.as_ptr(),
                bytes.len(),
                std::ptr::null(),
                std::ptr::null_mut(),
            )
        };
        assert_eq!(status, PpStatus::PpBadInput);
        assert!(last_error().contains("out_report_json"), "{}", last_error());
        unsafe { pp_machine_free(m) };
    }
}

/// A tool case: kind, diameter, corner radius, point, surface tolerance as the ABI takes
/// them; the `--tool` text, the point and the tolerance the library gets.
type Case = (
    PpToolKind,
    f64,
    f64,
    PpToolPoint,
    f64,
    &'static str,
    Option<polepatch::tool::ToolPoint>,
    f64,
);

/// What is refused, how it is set, and what the message says.
type Refusal = (&'static str, fn(&mut PpOptions), &'static str);

/// The tool fields of `PpOptions` are the library's `ToolOptions` (`--tool`,
/// `--tool-point`, `--surface-tolerance`): the same bytes and report on a ball at its tip,
/// a ball at its centre and a flat end mill; bad values refused with a message.
#[test]
fn tool_options_through_the_abi_are_the_librarys() {
    use polepatch::tool::{Tool, ToolOptions, ToolPoint};
    let name = "fixtures/c17/SING.I";
    let bytes = std::fs::read(root().join(name)).unwrap();
    let m = machine("mikron-ucp710");
    let rust_machine = Machine::builtin("mikron-ucp710").unwrap();
    let c_name = CString::new(name).unwrap();
    let cases: [Case; 4] = [
        (
            PpToolKind::PpToolBall,
            10.0,
            0.0,
            PpToolPoint::PpToolPointTip,
            0.0,
            "ball:10",
            Some(ToolPoint::Tip),
            0.005,
        ),
        (
            PpToolKind::PpToolBall,
            10.0,
            0.0,
            PpToolPoint::PpToolPointCentre,
            0.0,
            "ball:10",
            Some(ToolPoint::Centre),
            0.005,
        ),
        (
            PpToolKind::PpToolFlat,
            10.0,
            0.0,
            PpToolPoint::PpToolPointProgram,
            0.01,
            "flat:10",
            None,
            0.01,
        ),
        (
            PpToolKind::PpToolBull,
            10.0,
            2.0,
            PpToolPoint::PpToolPointProgram,
            0.0,
            "bull:10,2",
            None,
            0.005,
        ),
    ];
    for (kind, d, r, point, tol, spec, lib_point, lib_tol) in cases {
        let mut opts = pp_options_default();
        opts.name = c_name.as_ptr();
        opts.tool_kind = kind as i32;
        opts.tool_diameter_mm = d;
        opts.tool_corner_radius_mm = r;
        opts.tool_point = point as i32;
        opts.surface_tolerance_mm = tol;
        let mut out = PpBuffer {
            data: std::ptr::null_mut(),
            len: 0,
        };
        let mut report = PpBuffer {
            data: std::ptr::null_mut(),
            len: 0,
        };
        let status =
            unsafe { pp_patch_nc(m, bytes.as_ptr(), bytes.len(), &opts, &mut out, &mut report) };
        assert_eq!(status, PpStatus::PpOk, "{spec}: {}", last_error());
        let lib_opts = polepatch::PatchOptions {
            read: polepatch::ReadOptions {
                name: name.into(),
                ..polepatch::ReadOptions::default()
            },
            tool: ToolOptions {
                tool: Some(Tool::parse(spec).unwrap()),
                point: lib_point,
                surface_tolerance_mm: lib_tol,
                ..ToolOptions::default()
            },
            ..polepatch::PatchOptions::default()
        };
        let (want, want_report) = polepatch::patch_nc(&bytes, &rust_machine, &lib_opts).unwrap();
        assert_eq!(take(&mut out), want, "{spec}");
        let got = without_timing(&take(&mut report));
        assert_eq!(
            got,
            without_timing(&serde_json::to_vec_pretty(&want_report).unwrap()),
            "{spec}"
        );
        let described = Tool::parse(spec).unwrap().describe();
        for z in got["zones"].as_array().unwrap() {
            assert_eq!(z["tool"], described.as_str(), "{spec}");
            assert_eq!(z["tool_source"], "--tool", "{spec}");
        }
    }
    // Refusals: a kind, a point or a geometry the CLI's `--tool` refuses.
    let refused: [Refusal; 5] = [
        ("kind 4", |o| o.tool_kind = 4, "tool_kind must be 0…3"),
        (
            "bull without a corner radius",
            |o| {
                o.tool_kind = PpToolKind::PpToolBull as i32;
                o.tool_diameter_mm = 10.0;
            },
            "bull:D,R",
        ),
        (
            "ball without a diameter",
            |o| o.tool_kind = PpToolKind::PpToolBall as i32,
            "ball:D",
        ),
        ("point 3", |o| o.tool_point = 3, "tool_point must be 0…2"),
        (
            "NaN surface tolerance",
            |o| o.surface_tolerance_mm = f64::NAN,
            "surface_tolerance_mm",
        ),
    ];
    for (what, set, message) in refused {
        let mut opts = pp_options_default();
        set(&mut opts);
        let mut out = PpBuffer {
            data: std::ptr::null_mut(),
            len: 0,
        };
        let status = unsafe {
            pp_patch_nc(
                m,
                bytes.as_ptr(),
                bytes.len(),
                &opts,
                &mut out,
                std::ptr::null_mut(),
            )
        };
        assert_eq!(status, PpStatus::PpBadInput, "{what}");
        assert!(last_error().contains(message), "{what}: {}", last_error());
        assert!(out.data.is_null(), "{what}");
    }
    unsafe { pp_machine_free(m) };
}

/// Issue 28 §3: the patcher's one rule set behind the C ABI, each refusal naming the
/// `PpOptions` member: a negative cap (0 means no limit here), a negative margin, 12
/// decimals, G16's join option without the C-only method.
#[test]
fn options_are_refused_by_the_patchers_rules_naming_the_member() {
    let m = machine("mikron-ucp710");
    let text = std::fs::read(root().join("fixtures/c17/SING.I")).unwrap();
    type Case = (fn(&mut PpOptions), &'static str);
    let cases: [Case; 4] = [
        (
            |o| o.max_deviation_deg = -1.0,
            "PpOptions.max_deviation_deg must be a positive number of degrees, got -1",
        ),
        (
            |o| o.margin = -0.1,
            "PpOptions.margin must be a fraction in [0, 0.5), got -0.1",
        ),
        (
            |o| o.max_decimals = 12,
            "PpOptions.max_decimals must be at most 9, got 12",
        ),
        (
            |o| o.allow_c_offset = true,
            "PpOptions.allow_c_offset is G16's join option",
        ),
    ];
    for (change, want) in cases {
        let mut opts = pp_options_default();
        change(&mut opts);
        let mut out = PpBuffer {
            data: std::ptr::null_mut(),
            len: 0,
        };
        let status = unsafe {
            pp_patch_nc(
                m,
                text.as_ptr(),
                text.len(),
                &opts,
                &mut out,
                std::ptr::null_mut(),
            )
        };
        assert_eq!(status, PpStatus::PpBadInput, "{want}");
        assert!(last_error().starts_with(want), "{}", last_error());
        assert!(out.data.is_null());
    }
    unsafe { pp_machine_free(m) };
}
