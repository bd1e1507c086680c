//! Proof that the C ABI links: `tests/c/patch_file.c` is compiled with the system C
//! compiler against the static library and `include/polepatch.h`, run on
//! `fixtures/c17/SING.I`, and must write byte for byte what `polepatch::patch_nc` (the
//! CLI's pipeline) writes, with the same report. A Python `ctypes` example does the same
//! when `python3` is present. Skipped, with a message, where no C compiler exists.

use polepatch::kinematics::Machine;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The folder with `libpolepatch_capi.a` / `.so`, built for this test: `cargo test` builds
/// the library only as an rlib, so the C artefacts are built here, once per test process,
/// with the cargo that runs the tests, in the same target folder and the `test` profile
/// (cargo has released its lock while tests run, and the dependencies are already built
/// for that profile: only this crate is compiled and linked).
fn lib_dir() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let exe = std::env::current_exe().unwrap();
        // target/<profile>/deps/<test> → target
        let target = exe.ancestors().nth(3).unwrap().to_path_buf();
        let status = Command::new(env!("CARGO"))
            .args([
                "build",
                "--quiet",
                "--profile",
                "test",
                "-p",
                "polepatch-capi",
            ])
            .arg("--target-dir")
            .arg(&target)
            .current_dir(root())
            .status()
            .expect("cargo runs");
        assert!(status.success(), "building the C library failed");
        target.join("debug")
    })
    .clone()
}

/// Asserts that a program ran successfully, showing its output when not.
fn succeeded(run: &std::process::Output) {
    assert!(
        run.status.success(),
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

fn expected(name: &str, machine: &str) -> (Vec<u8>, String) {
    expected_with(name, machine, polepatch::tool::ToolOptions::default())
}

fn expected_with(
    name: &str,
    machine: &str,
    tool: polepatch::tool::ToolOptions,
) -> (Vec<u8>, String) {
    let m = Machine::builtin(machine).unwrap();
    let opts = polepatch::PatchOptions {
        read: polepatch::ReadOptions {
            name: name.into(),
            ..polepatch::ReadOptions::default()
        },
        tool,
        ..polepatch::PatchOptions::default()
    };
    let (out, report) =
        polepatch::patch_nc(&std::fs::read(root().join(name)).unwrap(), &m, &opts).unwrap();
    (out, serde_json::to_string_pretty(&report).unwrap())
}

/// The report without `solve_time_ms` (a measured time, different on every run).
fn without_timing(json: &str) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
    for z in v["zones"].as_array_mut().unwrap() {
        z.as_object_mut().unwrap().remove("solve_time_ms");
    }
    v
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("polepatch-capi-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Compile the C program against the static library. A missing C compiler fails the test
/// (it cannot pass without linking the ABI from C; Rust's own linking needs `cc` anyway).
fn compile(dir: &Path) -> PathBuf {
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    assert!(
        have(&cc),
        "no C compiler ('{cc}') on this machine: the C ABI cannot be linked from C (set CC)"
    );
    let exe = dir.join("patch_file");
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let status = Command::new(&cc)
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&exe)
        .arg(manifest.join("tests/c/patch_file.c"))
        .arg("-I")
        .arg(manifest.join("include"))
        .arg(lib_dir().join("libpolepatch_capi.a"))
        .args(["-lpthread", "-ldl", "-lm"])
        .status()
        .expect("the C compiler runs");
    assert!(status.success(), "compiling tests/c/patch_file.c failed");
    exe
}

#[test]
fn a_c_program_patches_sing_byte_for_byte() {
    let dir = temp("c");
    let exe = compile(&dir);
    // Each machine with a program posted for it (a B-C program on the B-C machine: an A-C
    // one is refused there, issue 29).
    // The ball run: `PpOptions.tool_*` are the library's `--tool ball:10 --tool-point tip`.
    let ball_tip = polepatch::tool::ToolOptions {
        tool: Some(polepatch::tool::Tool::parse("ball:10").unwrap()),
        point: Some(polepatch::tool::ToolPoint::Tip),
        ..polepatch::tool::ToolOptions::default()
    };
    for (machine, name) in [
        ("mikron-ucp710", "fixtures/c17/SING.I"),
        (
            "mikron-hsm600",
            "fixtures/generated/heidenhain-bc-swing-d0.1.I",
        ),
    ] {
        let (out, report) = (dir.join("out.I"), dir.join("report.json"));
        let (ball_out, ball_report) = (dir.join("ball.I"), dir.join("ball.json"));
        let run = Command::new(&exe)
            .arg(machine)
            .arg(root().join(name))
            .args([&out, &report])
            .arg(name)
            .args([&ball_out, &ball_report])
            .output()
            .unwrap();
        succeeded(&run);
        let (want, want_report) = expected(name, machine);
        assert_eq!(std::fs::read(&out).unwrap(), want, "{machine}");
        assert_eq!(
            without_timing(&std::fs::read_to_string(&report).unwrap()),
            without_timing(&want_report)
        );
        let (want, want_report) = expected_with(name, machine, ball_tip.clone());
        assert_eq!(std::fs::read(&ball_out).unwrap(), want, "{machine}, ball");
        let got = without_timing(&std::fs::read_to_string(&ball_report).unwrap());
        assert_eq!(got, without_timing(&want_report));
        let zones = got["zones"].as_array().unwrap();
        assert!(!zones.is_empty());
        for z in zones {
            assert_eq!(z["tool"], "ball D10", "{machine}");
            assert_eq!(z["tool_point"], "tip", "{machine}");
        }
    }
}

#[test]
fn the_python_ctypes_example_patches_sing_byte_for_byte() {
    assert!(
        have("python3"),
        "python3 is not installed (.ci/run installs it): the ctypes example cannot run"
    );
    let lib = lib_dir().join("libpolepatch_capi.so");
    let dir = temp("py");
    let out = dir.join("out.I");
    let name = "fixtures/c17/SING.I";
    let run = Command::new("python3")
        .arg(root().join("examples/python/patch_nc.py"))
        .arg(&lib)
        .arg("mikron-ucp710")
        .arg(root().join(name))
        .arg(&out)
        .output()
        .unwrap();
    succeeded(&run);
    let (want, _) = expected(name, "mikron-ucp710");
    assert_eq!(std::fs::read(&out).unwrap(), want);
}
