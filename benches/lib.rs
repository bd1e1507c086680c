//! Shared helpers for the criterion benches.

use polepatch_fixturegen::{Pass, joints};
use polepatch_kinematics::Machine;
use polepatch_patcher::Path;

/// One near-pole zone like those of programs nobody here has seen (issue 21's held-out
/// set): a generated pass and how it is patched.
#[derive(Debug, Clone)]
pub struct HeldOut {
    /// `machine/flip|swing/dD/Ffeed/hSpacing/pinned|free`.
    pub label: String,
    /// The machine.
    pub machine: Machine,
    /// The run (s = X, the tool tip runs along X).
    pub path: Path,
    /// The run's last point must stay (what follows it programs the rotary axes).
    pub keep_last_point: bool,
    /// Decimal places of the rotary words (what the NC pipeline reads from the file).
    pub decimals: usize,
}

/// splitmix64 in [0, 1), so the set is the same on every machine.
fn unit(state: &mut u64) -> f64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
}

/// `count` held-out-like zones from `seed`: feeds 800–5000 mm/min, spacings 0.25–1 mm,
/// flips (domain-rule posts) and swings (continuous branch) 0–5° from the pole, both
/// built-in machines, pinned and free ends, 3 or 4 decimals. Runs are long enough for a
/// C-only patch to exist (the tool axis' azimuth turns up to 180° near the pole).
pub fn held_out_zones(seed: u64, count: usize) -> Vec<HeldOut> {
    let mut st = seed;
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let b_axis = k % 2 == 1;
        let name = if b_axis {
            "mikron-hsm600"
        } else {
            "mikron-ucp710"
        };
        let machine = Machine::builtin(name).expect("built-in machine");
        let pick = |st: &mut u64, xs: &[f64]| {
            xs[((unit(st) * xs.len() as f64) as usize).min(xs.len() - 1)]
        };
        let feed = pick(&mut st, &[800.0, 1500.0, 2000.0, 3000.0, 5000.0]);
        let v_deg_mm = machine.limit(polepatch_kinematics::Axis::C).v / (feed / 60.0);
        let length_mm = (20.0 + 60.0 * unit(&mut st)).max(1.5 * 180.0 / v_deg_mm + 10.0);
        let spacing_mm = pick(&mut st, &[0.25, 0.5, 1.0]).max(length_mm / 300.0);
        let d = 5.0 * unit(&mut st);
        let domain_rule = unit(&mut st) < 0.5;
        let pinned = unit(&mut st) < 0.5;
        let decimals = if unit(&mut st) < 0.5 { 3 } else { 4 };
        let pass = Pass {
            pole_distance_deg: d,
            circle_radius_deg: 5.0 + 25.0 * unit(&mut st),
            half_sweep_deg: 30.0 + 60.0 * unit(&mut st),
            azimuth_deg: 360.0 * unit(&mut st),
            length_mm,
            spacing_mm,
            feed_mm_min: feed,
            b_axis,
            domain_rule,
            rotary_decimals: decimals,
        };
        let axes = joints(&pass);
        let path = Path {
            s_mm: axes.iter().map(|q| q[0]).collect(),
            axes,
            feed_mm_min: feed,
        };
        out.push(HeldOut {
            label: format!(
                "{name}/{}/d{d:.2}/F{feed}/h{spacing_mm}/{}",
                if domain_rule { "flip" } else { "swing" },
                if pinned { "pinned" } else { "free" }
            ),
            machine,
            path,
            keep_last_point: pinned,
            decimals,
        });
    }
    out
}

/// File style of a generated program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Heidenhain ISO: `%NAME G71 *`, `N` numbers, `+` signs, `*` block ends, every
    /// word written in every block.
    Heidenhain,
    /// Fanuc: `%`, `O` number, `( )` comments, G43.4, unsigned numbers with trailing
    /// points, modal omission of unchanged words.
    Fanuc,
}

/// A 5-axis G1 finishing program of at least `bytes` bytes in `style` with no point
/// near the pole: the tilting axis (letter `primary`, `'A'` or `'B'`) stays within
/// 20°–35°, so a patcher with the default 5° cone finds no zone. C sweeps through ±180°
/// and beyond like a real spiral. The feed alternates between F2000 and F2500 every 4000
/// blocks, so the program has many runs (about one per 4000 points).
pub fn no_zone_program(bytes: usize, style: Style, primary: char) -> Vec<u8> {
    let mut text = Vec::with_capacity(bytes + 256);
    let p = primary;
    match style {
        Style::Heidenhain => text.extend_from_slice(
            format!("%BIG G71 *\nN10 G90 *\nN20 T5 *\nN30 M128 *\nN40 G01 X+0 Y+0 Z-8 {p}+25 C+0 F2000 *\n").as_bytes(),
        ),
        Style::Fanuc => text.extend_from_slice(
            format!("%\nO1000 (NO ZONE)\nG90 G21\nT5 M6\nG43.4 H5\nG1 X0. Y0. Z-8. {p}25. C0. F2000.\n").as_bytes(),
        ),
    }
    let mut k = 0u64;
    let mut n = 50u64;
    use std::fmt::Write;
    let mut line = String::with_capacity(96);
    while text.len() < bytes {
        let t = k as f64;
        let x = t * 0.01 % 500.0;
        let y = (t * 0.001).sin() * 20.0;
        let a = 27.5 + (t * 0.0003).cos() * 7.5;
        let c = (t * 0.07) % 720.0 - 360.0;
        line.clear();
        let feed_change = k > 0 && k.is_multiple_of(4000);
        let feed = if (k / 4000).is_multiple_of(2) {
            2000
        } else {
            2500
        };
        match style {
            Style::Heidenhain => {
                let _ = write!(line, "N{n} X{x:+.3} Y{y:+.3} Z-8 {p}{a:+.3} C{c:+.3}");
                if feed_change {
                    let _ = write!(line, " F{feed}");
                }
                line.push_str(" *\n");
            }
            Style::Fanuc => {
                // Z never changes: omitted, as a Fanuc post does.
                let _ = write!(line, "X{x:.3} Y{y:.3} {p}{a:.3} C{c:.3}");
                if feed_change {
                    let _ = write!(line, " F{feed}.");
                }
                if k.is_multiple_of(1000) {
                    let _ = write!(line, " (P{k})");
                }
                line.push('\n');
            }
        }
        text.extend_from_slice(line.as_bytes());
        k += 1;
        n += 10;
    }
    text.extend_from_slice(match style {
        Style::Heidenhain => b"N999999 M30 *\n".as_slice(),
        Style::Fanuc => b"M30\n%\n".as_slice(),
    });
    text
}
