//! SPEC §6 accuracy study of the C-only method (`--only-c`): the max orientation deviation
//! of its patch against the best possible for C-only changes, per run with zones. (The
//! default method, both rotary axes, is measured by `polepatch bench`.)
//!
//! ```text
//! cargo run --release -p polepatch-patcher --example deviation_ratio [FILES…]
//! ```
//!
//! Without arguments: `fixtures/c17/SING.I` and a representative subset of
//! `fixtures/generated` (Heidenhain, both kinematics, flips and swings at pole distances
//! 0.01°, 0.5°, 2°, 4°). Each file is read with `polepatch_nc::parse` and `runs` (as the
//! CLI does), on both built-in machines. "bound" is [`deviation_bound_sampled`] over the
//! whole run (points 1..n−1, `BOUND_SAMPLES_PER_SPAN` samples per span, limits without margin); "ours" the largest exact
//! deviation of `patch_path`'s written values. Prints a Markdown table.

use polepatch_kinematics::Machine;
use polepatch_nc::{Dialect, modal, parse, primary_in_use, runs};
use polepatch_patcher::{
    CLimits, Outcome, PatchOptions, Path, patch_path, quality::deviation_bound_sampled,
    quality::orientation_deviation_deg,
};
use std::time::Instant;

fn default_files(root: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut v = vec![root.join("fixtures/c17/SING.I")];
    for kin in ["ac", "bc"] {
        for kind in ["flip", "swing"] {
            for d in ["0.01", "0.5", "2", "4"] {
                v.push(root.join(format!("fixtures/generated/heidenhain-{kin}-{kind}-d{d}.I")));
            }
        }
    }
    v
}

fn main() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let args: Vec<_> = std::env::args().skip(1).map(Into::into).collect();
    let files = if args.is_empty() {
        default_files(&root)
    } else {
        args
    };
    let opts = PatchOptions {
        axes: polepatch_patcher::PatchAxes::OnlyC,
        ..PatchOptions::default()
    };
    println!(
        "| file | machine | run pts | zones | outcome | ours ° | bound ° | ratio | solves | ms/zone |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let mut worst: f64 = 0.0;
    for f in &files {
        let bytes = std::fs::read(f).expect("readable fixture");
        let prog = parse(bytes, Dialect::Auto).expect("parsable fixture");
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        for mname in ["mikron-ucp710", "mikron-hsm600"] {
            let m = Machine::builtin(mname).unwrap();
            let rs = runs(&prog);
            let own = modal::RotaryLetters::new(m.primary_letter() as u8, m.c_letter() as u8)
                .expect("a built-in's letters are among A B C");
            let pi = primary_in_use(&rs, own);
            for r in &rs {
                let Some(feed) = r.feed_mm_min else { continue };
                let path = Path {
                    s_mm: r.s_mm.clone(),
                    axes: r.axes5(pi),
                    feed_mm_min: feed,
                };
                if path.s_mm.len() < 2 {
                    continue;
                }
                let t0 = Instant::now();
                let Ok(res) = patch_path(&path, &m, &opts) else {
                    continue;
                };
                let wall = t0.elapsed().as_secs_f64();
                if res.zones.is_empty() {
                    continue;
                }
                let n = path.s_mm.len();
                let p: Vec<f64> = path.axes.iter().map(|q| q[3]).collect();
                let c: Vec<f64> = path.axes.iter().map(|q| q[4]).collect();
                let ours = (0..n)
                    .map(|i| orientation_deviation_deg(p[i], res.c_deg[i] - c[i]))
                    .fold(0.0, f64::max);
                let lim0 = CLimits::new(&m, feed, 0.0);
                let bound = deviation_bound_sampled(
                    &path.s_mm,
                    &p,
                    &c,
                    1,
                    n - 1,
                    &lim0,
                    polepatch_patcher::quality::BOUND_SAMPLES_PER_SPAN,
                )
                .ok()
                .map(|b| b.0);
                let ratio = bound.map(|b| if b > 0.0 { ours / b } else { f64::NAN });
                if let Some(r) = ratio
                    && r.is_finite()
                {
                    worst = worst.max(r);
                }
                let outcomes: Vec<&str> = res
                    .zones
                    .iter()
                    .map(|z| match z.outcome {
                        Outcome::Reached => "R",
                        Outcome::Improved => "I",
                        Outcome::Unchanged => "U",
                    })
                    .collect();
                let solves: u32 = res.zones.iter().map(|z| z.qp.solves).sum();
                println!(
                    "| {name} | {mname} | {n} | {} | {} | {ours:.3} | {} | {} | {solves} | {:.2} |",
                    res.zones.len(),
                    outcomes.join(""),
                    bound.map_or("—".into(), |b| format!("{b:.3}")),
                    ratio.map_or("—".into(), |r| format!("{r:.3}")),
                    1e3 * wall / res.zones.len() as f64,
                );
            }
        }
    }
    println!("\nworst ratio: {worst:.3}");
}
