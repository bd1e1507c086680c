//! `polepatch verify ORIGINAL PATCHED` (issue 39): exit 0 and one summary line when the
//! written program holds against its input; exit 1 naming `file:line` and the check for
//! each line that does not (a feed word changed, a point moved, a line deleted), the same
//! as JSON with `--json`.

mod common;

use common::{polepatch, temp_dir};

/// SING patched, then planted: the check of each plant names its line.
#[test]
fn verify_names_each_line_that_does_not_hold() {
    let dir = temp_dir("verify-cli");
    let patched = dir.join("SING.patched.I");
    let p = patched.to_str().unwrap();
    let (code, _, err) = polepatch(&[
        "patch",
        "fixtures/c17/SING.I",
        "-m",
        "mikron-ucp710",
        "-o",
        p,
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = polepatch(&["verify", "fixtures/c17/SING.I", p, "-m", "mikron-ucp710"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.starts_with("verified: "), "{out}");
    let text = std::fs::read_to_string(&patched).unwrap();
    let planted = |what: &str, edit: &dyn Fn(&mut Vec<String>)| -> String {
        let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
        edit(&mut lines);
        let f = dir.join(format!("{what}.I"));
        std::fs::write(&f, lines.join("\n") + "\n").unwrap();
        f.to_str().unwrap().to_string()
    };
    // A feed word changed (line 12), a patched point's X moved by 0.01 mm (line 20), a
    // line deleted (line 30).
    let feed = planted("feed", &|l| l[11] = l[11].replace("F2000", "F2500"));
    let moved = planted("moved", &|l| {
        let x = l[19]
            .split_whitespace()
            .find(|w| w.starts_with('X'))
            .unwrap()
            .to_string();
        let v: f64 = x[1..].parse().unwrap();
        l[19] = l[19].replacen(&x, &format!("X{:+.3}", v + 0.01), 1);
    });
    let deleted = planted("deleted", &|l| {
        l.remove(29);
    });
    for (f, line) in [(&feed, 12), (&moved, 20), (&deleted, 30)] {
        let (code, out, err) =
            polepatch(&["verify", "fixtures/c17/SING.I", f, "-m", "mikron-ucp710"]);
        assert_eq!(code, 1, "{f}: {out}{err}");
        assert!(out.contains(&format!("{f}:{line}: ")), "{f}: {out}");
        assert!(
            out.lines().last().unwrap().starts_with("NOT verified: "),
            "{out}"
        );
        let (code, json, _) = polepatch(&[
            "verify",
            "fixtures/c17/SING.I",
            f,
            "-m",
            "mikron-ucp710",
            "--json",
        ]);
        assert_eq!(code, 1);
        let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
        let lines: Vec<u64> = doc["violations"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v["line"].as_u64().unwrap())
            .collect();
        assert!(lines.contains(&line), "{f}: {lines:?}");
    }
}
