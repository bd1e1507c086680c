//! The independent references of issue 43 item 5 (`tests/reference/reference.py`: Ruckig
//! for lines, TOPP-RA for joint paths), asked through a Python interpreter that has the
//! PyPI packages `ruckig` and `toppra`: `$POLEPATCH_REFERENCE_PYTHON`, else
//! `target/reference-venv/bin/python` of the workspace (`.ci/run` makes it). Without one,
//! the tests that use it say that they skipped and why.

#![allow(dead_code)]

use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Stdio};

/// The reference script.
pub fn script() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../simulate/tests/reference/reference.py")
}

/// The interpreter to ask, or why there is none.
pub fn python() -> Result<PathBuf, String> {
    let candidates: Vec<PathBuf> = match std::env::var_os("POLEPATCH_REFERENCE_PYTHON") {
        Some(p) => vec![PathBuf::from(p)],
        None => vec![
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../target/reference-venv/bin/python"),
        ],
    };
    for p in &candidates {
        let ok = Command::new(p)
            .args(["-c", "import ruckig, toppra"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success());
        if ok {
            return Ok(p.clone());
        }
    }
    Err(format!(
        "no Python with the PyPI packages ruckig and toppra ({}; set POLEPATCH_REFERENCE_PYTHON \
         or run `python3 -m venv target/reference-venv && target/reference-venv/bin/pip install \
         ruckig toppra`, as .ci/run does)",
        candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// The reference's time for the JSON request `req`, s.
pub fn time_s(python: &PathBuf, req: &str) -> f64 {
    let mut child = Command::new(python)
        .arg(script())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs the reference");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(req.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "reference failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    text.trim()
        .trim_start_matches("{\"time_s\":")
        .trim_end_matches('}')
        .trim()
        .parse()
        .unwrap_or_else(|e| panic!("reference answered {text}: {e}"))
}

/// `xs` as a JSON array.
pub fn json_list(xs: impl IntoIterator<Item = f64>) -> String {
    let v: Vec<String> = xs.into_iter().map(|x| format!("{x:e}")).collect();
    format!("[{}]", v.join(","))
}
