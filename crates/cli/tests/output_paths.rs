//! Issue 19 §3: one output-path policy for every command and every file it writes
//! (`crates/cli/src/outputs.rs`, docs/output-paths.md). Every refused case: exit 1, a
//! message naming both paths, nothing written, the inputs' bytes unchanged.

mod common;
use common::{polepatch, polepatch_in, root, temp_dir};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn sing() -> Vec<u8> {
    std::fs::read(root().join("fixtures/c17/SING.I")).unwrap()
}

fn non_sing() -> Vec<u8> {
    std::fs::read(root().join("fixtures/c17/NON_SING.I")).unwrap()
}

/// Every entry under `dir` (recursively, links not followed): path → bytes (regular
/// files), `link → target` (links) or the kind (anything else).
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let m = std::fs::symlink_metadata(&p).unwrap();
            let rel = p.strip_prefix(dir).unwrap().to_path_buf();
            if m.is_dir() {
                out.insert(rel, b"<dir>".to_vec());
                stack.push(p);
            } else if m.file_type().is_symlink() {
                let t = std::fs::read_link(&p).unwrap();
                out.insert(rel, format!("-> {}", t.display()).into_bytes());
            } else if m.is_file() {
                out.insert(rel, std::fs::read(&p).unwrap());
            } else {
                out.insert(rel, b"<special>".to_vec());
            }
        }
    }
    out
}

/// Run `args` in `dir` and check the refusal: exit 1, every one of `names` in the
/// message, the folder exactly as it was.
fn refused(dir: &Path, args: &[&str], names: &[&str]) -> String {
    let before = snapshot(dir);
    let (code, _, err) = polepatch_in(dir, args);
    assert_eq!(code, 1, "{args:?}: {err}");
    for n in names {
        assert!(err.contains(n), "{args:?}: the message lacks {n}: {err}");
    }
    assert_eq!(err.matches("error:").count(), 1, "one message: {err}");
    assert_eq!(snapshot(dir), before, "{args:?} wrote or changed something");
    err
}

fn m() -> [&'static str; 2] {
    ["--machine", "mikron-ucp710"]
}

#[test]
fn a_report_or_csv_onto_an_input_file_is_refused() {
    let dir = temp_dir("op-onto");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    for flag in ["--report", "--csv"] {
        let mut args = vec!["patch", "SING.I", "-o", "out.I", flag, "./SING.I"];
        args.extend(m());
        let err = refused(&dir, &args, &["./SING.I", "the input SING.I"]);
        assert!(
            err.contains(&format!("{flag} ./SING.I is the input")),
            "{err}"
        );
    }
}

/// The report named as a file inside an input folder that is one of the inputs.
#[test]
fn a_report_or_csv_inside_an_input_folder_is_refused_when_it_is_an_input() {
    let dir = temp_dir("op-folder");
    std::fs::create_dir_all(dir.join("in")).unwrap();
    std::fs::write(dir.join("in/a.I"), sing()).unwrap();
    std::fs::write(dir.join("in/b.I"), non_sing()).unwrap();
    for flag in ["--report", "--csv"] {
        let mut args = vec!["patch", "in", "--out-dir", "out", flag, "in/b.I"];
        args.extend(m());
        refused(
            &dir,
            &args,
            &[&format!("{flag} in/b.I"), "the input in/b.I"],
        );
    }
    // A new file in the input folder is not an input: written.
    let mut args = vec!["patch", "in", "--out-dir", "out", "--report", "in/r.json"];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("in/r.json").is_file());
    assert_eq!(std::fs::read(dir.join("in/b.I")).unwrap(), non_sing());
}

#[test]
fn post_report_onto_the_cl_input_is_refused() {
    let dir = temp_dir("op-post");
    std::fs::copy(root().join("fixtures/cl/SING.apt"), dir.join("SING.apt")).unwrap();
    let mut args = vec![
        "post",
        "SING.apt",
        "--dialect",
        "heidenhain",
        "-o",
        "out.I",
        "--report",
        "SING.apt",
    ];
    args.extend(m());
    refused(&dir, &args, &["--report SING.apt", "the CL input SING.apt"]);
}

#[test]
fn reorient_plot_onto_the_input_is_refused() {
    let dir = temp_dir("op-plot");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    let mut args = vec![
        "reorient",
        "SING.I",
        "--theta-x",
        "10",
        "--theta-z",
        "180",
        "--plot",
        "SING.I",
    ];
    args.extend(m());
    refused(&dir, &args, &["--plot SING.I", "the input SING.I"]);
}

#[test]
fn two_outputs_on_one_path_are_refused() {
    let dir = temp_dir("op-two");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    std::fs::create_dir_all(dir.join("d")).unwrap();
    let mut args = vec!["patch", "SING.I", "-o", "X.I", "--report", "d/../X.I"];
    args.extend(m());
    refused(&dir, &args, &["-o X.I", "--report d/../X.I"]);
    let mut args = vec![
        "reorient",
        "SING.I",
        "--theta-x",
        "10",
        "--theta-z",
        "180",
        "-o",
        "X.I",
        "--plot",
        "./X.I",
    ];
    args.extend(m());
    refused(&dir, &args, &["-o X.I", "--plot ./X.I"]);
    // The same file under two names: an existing file and a hard link to it.
    std::fs::write(dir.join("old.I"), b"old").unwrap();
    std::fs::hard_link(dir.join("old.I"), dir.join("hard.I")).unwrap();
    let mut args = vec!["patch", "SING.I", "-o", "old.I", "--csv", "hard.I"];
    args.extend(m());
    refused(&dir, &args, &["-o old.I", "--csv hard.I"]);
}

#[test]
fn a_batch_with_two_inputs_of_one_file_name_is_refused_before_writing() {
    let dir = temp_dir("op-batch");
    for d in ["a", "b"] {
        std::fs::create_dir_all(dir.join(d)).unwrap();
    }
    std::fs::write(dir.join("a/x.I"), sing()).unwrap();
    std::fs::write(dir.join("b/x.I"), non_sing()).unwrap();
    let mut args = vec!["patch", "a/x.I", "b/x.I", "--out-dir", "o"];
    args.extend(m());
    refused(&dir, &args, &["o/x.I (from a/x.I)", "o/x.I (from b/x.I)"]);
    // An output that the batch also reads as an input (o/x.I, given second).
    std::fs::create_dir_all(dir.join("o")).unwrap();
    std::fs::write(dir.join("o/x.I"), non_sing()).unwrap();
    let mut args = vec!["patch", "a/x.I", "o/x.I", "--out-dir", "o"];
    args.extend(m());
    refused(&dir, &args, &["o/x.I (from a/x.I)", "the input o/x.I"]);
    std::fs::remove_dir_all(dir.join("o")).unwrap();
    // The folders given instead: each output under its folder's name.
    let mut args = vec!["patch", "a", "b", "--out-dir", "o"];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    assert!(dir.join("o/a/x.I").is_file() && dir.join("o/b/x.I").is_file());
    assert_eq!(std::fs::read(dir.join("o/b/x.I")).unwrap(), non_sing());
}

/// `patch .. --out-dir o` from a subfolder wrote outside `o/` and overwrote another input.
#[test]
fn parent_folder_inputs_stay_under_out_dir() {
    let dir = temp_dir("op-up");
    let work = dir.join("work");
    std::fs::create_dir_all(work.join("sub")).unwrap();
    std::fs::write(work.join("x.I"), sing()).unwrap();
    std::fs::write(work.join("sub/y.I"), non_sing()).unwrap();
    let sub = work.join("sub");
    let mut args = vec!["patch", "..", "../x.I", "--out-dir", "o"];
    args.extend(m());
    // `..` holds x.I, and x.I is also given: o/x.I and o/work/x.I, no clash.
    let (code, _, err) = polepatch_in(&sub, &args);
    assert_eq!(code, 0, "{err}");
    let written = snapshot(&sub.join("o"));
    let files: Vec<String> = written
        .iter()
        .filter(|(_, v)| v.as_slice() != b"<dir>")
        .map(|(k, _)| k.display().to_string())
        .collect();
    assert_eq!(files, ["work/sub/y.I", "work/x.I", "x.I"], "{written:?}");
    // Nothing outside o/: the inputs are as they were, no other file appeared.
    assert_eq!(std::fs::read(work.join("x.I")).unwrap(), sing());
    assert_eq!(std::fs::read(work.join("sub/y.I")).unwrap(), non_sing());
    assert_eq!(
        std::fs::read_dir(&work).unwrap().count(),
        2,
        "x.I and sub/ only"
    );
    // Run again: the outputs of the first run (sub/o, inside the input folder) are not
    // read as inputs.
    let (code, _, err) = polepatch_in(&sub, &args);
    assert_eq!(code, 0, "{err}");
    assert!(!sub.join("o/work/sub/o").exists());
    // A batch output that would leave --out-dir through a link in it is refused.
    std::fs::remove_dir_all(sub.join("o")).unwrap();
    std::fs::create_dir_all(sub.join("o")).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("elsewhere.I"), sub.join("o/x.I")).unwrap();
        std::fs::write(dir.join("elsewhere.I"), b"keep").unwrap();
        let mut args = vec!["patch", "../x.I", "--out-dir", "o"];
        args.extend(m());
        refused(&sub, &args, &["o/x.I (from ../x.I)", "outside --out-dir o"]);
        assert_eq!(std::fs::read(dir.join("elsewhere.I")).unwrap(), b"keep");
    }
}

/// `-o /dev/null` as root replaced the device node with a regular file; a FIFO was replaced
/// too. Both are written through.
#[cfg(unix)]
#[test]
fn devices_and_fifos_are_written_through() {
    use std::os::unix::fs::FileTypeExt;
    let dir = temp_dir("op-dev");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    let mut args = vec![
        "patch",
        "SING.I",
        "-o",
        "/dev/null",
        "--report",
        "/dev/null",
    ];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    let meta = std::fs::metadata("/dev/null").unwrap();
    assert!(
        meta.file_type().is_char_device(),
        "/dev/null is no longer a device"
    );
    assert_eq!(
        snapshot(&dir).len(),
        1,
        "nothing but the input in the folder"
    );

    let mkfifo = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe"))
        .status();
    if !mkfifo.is_ok_and(|s| s.success()) {
        eprintln!("skipped the FIFO case: no mkfifo command on this machine");
        return;
    }
    // A reader on the FIFO, as `cat pipe > got` would be.
    let pipe = dir.join("pipe");
    let reader = std::thread::spawn(move || std::fs::read(pipe).unwrap());
    let mut args = vec!["patch", "SING.I", "-o", "pipe"];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    let got = reader.join().unwrap();
    assert!(
        std::fs::symlink_metadata(dir.join("pipe"))
            .unwrap()
            .file_type()
            .is_fifo(),
        "the FIFO was replaced"
    );
    let mut args = vec!["patch", "SING.I", "-o", "file.I"];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    assert_eq!(got, std::fs::read(dir.join("file.I")).unwrap());
    // Two outputs on one FIFO are refused like two on one file.
    let mut args = vec!["patch", "SING.I", "-o", "pipe", "--report", "pipe"];
    args.extend(m());
    refused(&dir, &args, &["-o pipe", "--report pipe"]);
}

/// A symbolic link at the output path is followed: the file it points to is replaced and
/// the link stays; a link to an input, or a dangling one, is refused.
#[cfg(unix)]
#[test]
fn a_symlink_at_the_output_is_followed() {
    use std::os::unix::fs::{PermissionsExt, symlink};
    let dir = temp_dir("op-link");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    std::fs::create_dir_all(dir.join("real")).unwrap();
    std::fs::write(dir.join("real/target.I"), b"old").unwrap();
    std::fs::set_permissions(
        dir.join("real/target.I"),
        std::fs::Permissions::from_mode(0o600),
    )
    .unwrap();
    symlink("real/target.I", dir.join("link.I")).unwrap();
    let mut args = vec!["patch", "SING.I", "-o", "link.I"];
    args.extend(m());
    let (code, _, err) = polepatch_in(&dir, &args);
    assert_eq!(code, 0, "{err}");
    assert!(
        std::fs::symlink_metadata(dir.join("link.I"))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    let written = std::fs::read(dir.join("real/target.I")).unwrap();
    assert_ne!(written, b"old");
    assert!(written.starts_with(b"%SING"));
    let mode = std::fs::metadata(dir.join("real/target.I"))
        .unwrap()
        .permissions()
        .mode();
    assert_eq!(
        mode & 0o777,
        0o600,
        "the replaced file keeps its permissions"
    );
    // No temporary file left beside the link or the target.
    for d in [&dir, &dir.join("real")] {
        assert!(
            !snapshot(d)
                .keys()
                .any(|k| k.to_string_lossy().contains(".polepatch-tmp-"))
        );
    }
    symlink("SING.I", dir.join("to_input.I")).unwrap();
    let mut args = vec!["patch", "SING.I", "-o", "to_input.I"];
    args.extend(m());
    refused(&dir, &args, &["-o to_input.I", "the input SING.I"]);
    symlink("nowhere/none.I", dir.join("dangling.I")).unwrap();
    let mut args = vec!["patch", "SING.I", "-o", "dangling.I"];
    args.extend(m());
    refused(&dir, &args, &["-o dangling.I", "nowhere/none.I"]);
}

/// The machine file is an input too.
#[test]
fn the_machine_file_is_never_an_output() {
    let dir = temp_dir("op-machine");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    std::fs::copy(
        root().join("crates/kinematics/machines/mikron-ucp710.toml"),
        dir.join("m.toml"),
    )
    .unwrap();
    refused(
        &dir,
        &[
            "patch",
            "SING.I",
            "-o",
            "out.I",
            "--machine",
            "m.toml",
            "--report",
            "m.toml",
        ],
        &["--report m.toml", "the machine file m.toml"],
    );
}

/// SIGTERM (and SIGINT) while an output is being written: its temporary file, named for
/// what it is, is removed and nothing is put in place.
#[cfg(unix)]
#[test]
fn temporary_files_are_removed_on_sigterm() {
    let dir = temp_dir("op-signal");
    // NON_SING repeated: every run starts on the pole and is analysed (seconds of work).
    let text = String::from_utf8(non_sing()).unwrap();
    let start = text.find("N65 M128").unwrap();
    let end = text.find("N670").unwrap();
    let mut big = text[..start].to_string();
    while big.len() < 12_000_000 {
        big.push_str(&text[start..end]);
    }
    std::fs::write(dir.join("big.I"), &big).unwrap();
    for signal in ["TERM", "INT"] {
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_polepatch"))
            .args([
                "patch",
                "big.I",
                "-o",
                "big.out.I",
                "--machine",
                "mikron-ucp710",
            ])
            .current_dir(&dir)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let temp = |d: &Path| {
            std::fs::read_dir(d)
                .unwrap()
                .filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .find(|n| n.starts_with(".big.out.I.polepatch-tmp-"))
        };
        let t0 = std::time::Instant::now();
        while temp(&dir).is_none() {
            assert!(
                child.try_wait().unwrap().is_none(),
                "finished before its temporary file was seen: make the input bigger"
            );
            assert!(t0.elapsed().as_secs() < 60, "no temporary file appeared");
            std::thread::sleep(std::time::Duration::from_millis(2));
        }
        let killed = std::process::Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let code = out.status.code();
        let want = if signal == "TERM" { 143 } else { 130 };
        assert_eq!(code, Some(want), "{err}");
        assert!(err.contains("temporary file(s) removed"), "{err}");
        assert_eq!(temp(&dir), None, "the temporary file is left");
        assert!(!dir.join("big.out.I").exists());
    }
}

#[test]
fn a_refused_plan_of_bench_writes_nothing() {
    let dir = temp_dir("op-bench");
    std::fs::write(dir.join("SING.I"), sing()).unwrap();
    refused(
        &dir,
        &[
            "bench",
            "SING.I",
            "--machine",
            "mikron-ucp710",
            "--no-bound",
            "--csv",
            "SING.I",
        ],
        &["--csv SING.I", "the input SING.I"],
    );
    let (code, _, err) = polepatch(&[
        "bench",
        dir.join("SING.I").to_str().unwrap(),
        "--machine",
        "mikron-ucp710",
        "--no-bound",
        "--json",
        dir.join("b.json").to_str().unwrap(),
        "--csv",
        dir.join("b.json").to_str().unwrap(),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("are the same file"), "{err}");
    assert!(!dir.join("b.json").exists());
}

/// Plots of two programs with one file stem (in different folders) would share a name.
#[test]
fn bench_plots_of_one_name_are_refused_before_writing() {
    let dir = temp_dir("op-plots");
    for d in ["a", "b"] {
        std::fs::create_dir_all(dir.join(d)).unwrap();
        std::fs::write(dir.join(d).join("SING.I"), sing()).unwrap();
    }
    let args = [
        "bench",
        "a",
        "b",
        "--machine",
        "mikron-ucp710",
        "--no-bound",
        "--plots",
        "plots",
        "--json",
        "b.json",
    ];
    refused(
        &dir,
        &args,
        &[
            "the plot plots/SING-mikron-ucp710-run1-zone1.svg",
            "are the same file",
        ],
    );
}
