//! Synthetic near-pole programs.
//!
//! The tool tip runs along a straight line in X; the tool axis follows a small circle on
//! the unit sphere (angular radius `circle_radius_deg`) whose closest approach to the pole
//! is `pole_distance_deg` (0 = exactly through the pole), reached halfway along the line.
//! Joint values come from inverse kinematics with either the G16 Table 1 domain rule (the
//! primary axis flips sign, C jumps up to 180°) or a continuous branch (C swings, the
//! primary keeps its sign, as in C17's `%SING`). The program is written in Heidenhain ISO,
//! Sinumerik or Fanuc style for an A-C or a B-C machine (G16 senses: sp = sc = +1).

use polepatch_kinematics::{BranchRule, Machine, inverse_path};
use std::fmt::Write as _;

/// Dialect of the written program.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dialect {
    /// Heidenhain ISO: `%NAME G71 *`, `N10 G01 X+1 … *`, M128.
    Heidenhain,
    /// Sinumerik: `;` comments, TRAORI, CRLF line ends.
    Sinumerik,
    /// Fanuc: `%`, `O1000`, `( )` comments, G43.4, modal omission of unchanged words.
    Fanuc,
}

impl Dialect {
    /// All dialects.
    pub const ALL: [Dialect; 3] = [Dialect::Heidenhain, Dialect::Sinumerik, Dialect::Fanuc];
    /// Short name used in file names.
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Heidenhain => "heidenhain",
            Dialect::Sinumerik => "sinumerik",
            Dialect::Fanuc => "fanuc",
        }
    }
    /// File extension.
    pub fn extension(self) -> &'static str {
        match self {
            Dialect::Heidenhain => "I",
            Dialect::Sinumerik => "mpf",
            Dialect::Fanuc => "nc",
        }
    }
}

/// One synthetic pass.
#[derive(Debug, Clone, PartialEq)]
pub struct Pass {
    /// Closest angular distance of the tool axis to the pole, degrees (≥ 0).
    pub pole_distance_deg: f64,
    /// Angular radius of the tool-axis circle, degrees.
    pub circle_radius_deg: f64,
    /// Half the arc of the circle swept, degrees (the pass goes from −this to +this).
    pub half_sweep_deg: f64,
    /// Azimuth of the closest approach about Z, degrees (rotates the whole pass).
    pub azimuth_deg: f64,
    /// Length of the tool-tip line, mm.
    pub length_mm: f64,
    /// Spacing of the CL points, mm.
    pub spacing_mm: f64,
    /// Programmed feed, mm/min.
    pub feed_mm_min: f64,
    /// Primary axis letter: A-C (`false`) or B-C (`true`) machine.
    pub b_axis: bool,
    /// Domain rule (primary flips) instead of a continuous branch.
    pub domain_rule: bool,
    /// Decimal places of the written rotary values.
    pub rotary_decimals: usize,
}

impl Default for Pass {
    fn default() -> Self {
        Pass {
            pole_distance_deg: 0.5,
            circle_radius_deg: 15.0,
            half_sweep_deg: 60.0,
            azimuth_deg: 0.0,
            length_mm: 50.0,
            spacing_mm: 1.0,
            feed_mm_min: 2000.0,
            b_axis: false,
            domain_rule: false,
            rotary_decimals: 3,
        }
    }
}

fn rot_z(v: [f64; 3], a: f64) -> [f64; 3] {
    let (s, c) = a.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

/// The kinematic model used to write joint values: G16 senses, A or B primary.
pub fn machine(b_axis: bool) -> Machine {
    let name = if b_axis {
        "mikron-hsm600"
    } else {
        "mikron-ucp710"
    };
    let mut m = Machine::builtin(name).expect("built-in machine");
    m.primary_sense = 1.0;
    m.c_sense = 1.0;
    m.primary_range_deg = (-120.0, 120.0);
    m
}

/// CL points of a pass: tool tip (X, Y, Z) in mm and tool axis (i, j, k).
pub fn cl_points(p: &Pass) -> Vec<([f64; 3], [f64; 3])> {
    let n = (p.length_mm / p.spacing_mm).round().max(2.0) as usize;
    let rho = p.circle_radius_deg.to_radians();
    let tc = (p.pole_distance_deg + p.circle_radius_deg).to_radians();
    let c = [tc.sin(), 0.0, tc.cos()];
    let u = [-tc.cos(), 0.0, tc.sin()];
    let v = [0.0, 1.0, 0.0];
    let az = p.azimuth_deg.to_radians();
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let phi = (2.0 * t - 1.0) * p.half_sweep_deg.to_radians();
            let mut o = [0.0; 3];
            for d in 0..3 {
                o[d] = rho.cos() * c[d] + rho.sin() * (phi.cos() * u[d] + phi.sin() * v[d]);
            }
            let norm = (o[0] * o[0] + o[1] * o[1] + o[2] * o[2]).sqrt();
            let o = rot_z([o[0] / norm, o[1] / norm, o[2] / norm], az);
            ([t * p.length_mm, 0.0, -5.0], o)
        })
        .collect()
}

/// Joint values (X, Y, Z, P, C) of a pass, rounded as they will be written.
pub fn joints(p: &Pass) -> Vec<[f64; 5]> {
    let pts = cl_points(p);
    let o: Vec<[f64; 3]> = pts.iter().map(|q| q.1).collect();
    let rule = if p.domain_rule {
        BranchRule::DomainRule
    } else {
        BranchRule::Nearest
    };
    let sol = inverse_path(&machine(p.b_axis), &o, rule);
    let scale = 10f64.powi(p.rotary_decimals as i32);
    pts.iter()
        .zip(sol)
        .map(|(q, s)| {
            let r = |v: f64| (v * scale).round() / scale;
            [q.0[0], q.0[1], q.0[2], r(s.p_deg), r(s.c_deg)]
        })
        .collect()
}

fn num(v: f64, decimals: usize, plus: bool) -> String {
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".into();
    }
    if plus && !s.starts_with('-') {
        s.insert(0, '+');
    }
    s
}

/// The program text of a pass in `dialect`, named `name`.
pub fn program(p: &Pass, dialect: Dialect, name: &str) -> String {
    let j = joints(p);
    let pl = if p.b_axis { 'B' } else { 'A' };
    let d = p.rotary_decimals;
    let f = num(p.feed_mm_min, 0, false);
    let mut out = String::new();
    let nl = if dialect == Dialect::Sinumerik {
        "\r\n"
    } else {
        "\n"
    };
    let mut line = |s: String| {
        out.push_str(&s);
        out.push_str(nl);
    };
    let describe = format!(
        "pole distance {} deg, circle {} deg, {}, {}-C",
        p.pole_distance_deg,
        p.circle_radius_deg,
        if p.domain_rule {
            "domain rule"
        } else {
            "continuous branch"
        },
        pl
    );
    match dialect {
        Dialect::Heidenhain => {
            line(format!("%{name} G71 *"));
            line(format!("; {describe} *"));
            line("N10 G90 *".into());
            line("N20 T1 M6 *".into());
            line("N30 S12000 M3 *".into());
            line("N40 M128 *".into());
            let mut n = 50;
            for (k, q) in j.iter().enumerate() {
                let head = if k == 0 { "G01 " } else { "" };
                let feed = if k == 0 {
                    format!(" F{f}")
                } else {
                    String::new()
                };
                line(format!(
                    "N{n} {head}X{} Y{} Z{} {pl}{} C{}{feed} *",
                    num(q[0], 3, true),
                    num(q[1], 3, true),
                    num(q[2], 3, true),
                    num(q[3], d, true),
                    num(q[4], d, true)
                ));
                n += 10;
            }
            line(format!("N{n} M129 *"));
            line(format!("N{} M30 *", n + 10));
            line(format!("N999999 %{name} G71 *"));
        }
        Dialect::Sinumerik => {
            line(format!("; {name}: {describe}"));
            line("G90 G17 G71".into());
            line("T1 D1".into());
            line("M6".into());
            line("S12000 M3".into());
            line("TRAORI".into());
            for (k, q) in j.iter().enumerate() {
                let feed = if k == 0 {
                    format!(" F{f}")
                } else {
                    String::new()
                };
                let head = if k == 0 { "G1 " } else { "" };
                line(format!(
                    "{head}X{} Y{} Z{} {pl}={} C={}{feed}",
                    num(q[0], 3, false),
                    num(q[1], 3, false),
                    num(q[2], 3, false),
                    num(q[3], d, false),
                    num(q[4], d, false)
                ));
            }
            line("TRAFOOF".into());
            line("M30".into());
        }
        Dialect::Fanuc => {
            line("%".into());
            line("O1000".into());
            line(format!("({describe})"));
            line("G90 G21 G94".into());
            line("T1 M6".into());
            line("S12000 M3".into());
            line("G43.4 H1".into());
            let mut prev: Option<[String; 5]> = None;
            for (k, q) in j.iter().enumerate() {
                let w = [
                    num(q[0], 3, false),
                    num(q[1], 3, false),
                    num(q[2], 3, false),
                    num(q[3], d, false),
                    num(q[4], d, false),
                ];
                let letters = ['X', 'Y', 'Z', pl, 'C'];
                let mut s = String::new();
                if k == 0 {
                    s.push_str("G1");
                }
                for i in 0..5 {
                    if prev.as_ref().is_none_or(|p| p[i] != w[i]) {
                        if !s.is_empty() {
                            s.push(' ');
                        }
                        let _ = write!(s, "{}{}", letters[i], w[i]);
                    }
                }
                if k == 0 {
                    let _ = write!(s, " F{f}");
                }
                if !s.is_empty() {
                    line(s);
                }
                prev = Some(w);
            }
            line("G49".into());
            line("M30".into());
            line("%".into());
        }
    }
    out
}

/// A program form shops run that is not one of [`Dialect`]'s ISO styles (issue 20): the
/// same pass, written as each controller's users write it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ShopForm {
    /// Heidenhain conversational with `FUNCTION TCPM` / `FUNCTION RESET TCPM`.
    ConversationalFunctionTcpm,
    /// Heidenhain conversational with `M128` / `M129`.
    ConversationalM128,
    /// Fanuc/Haas with `G43.4` and inverse-time feed (`G93`, F = 1/min per block).
    FanucInverseTime,
    /// LinuxCNC: spaces inside words, `G93`, TCP switched by `M428`/`M429` (a machine file
    /// names them: `[controller] tcpm_on = ["M428"]`).
    LinuxCncInverseTime,
    /// A machine whose kinematics are always TCP (`tcpm_always = true`): no TCPM code.
    AlwaysTcp,
    /// Fanuc with spaces between address and number (`X 6.302  A -71.841`).
    SpacedWords,
    /// Fanuc with a first run whose rotary words are variables (`A#101`), then the pass.
    Variables,
}

impl ShopForm {
    /// Every form.
    pub const ALL: [ShopForm; 7] = [
        ShopForm::ConversationalFunctionTcpm,
        ShopForm::ConversationalM128,
        ShopForm::FanucInverseTime,
        ShopForm::LinuxCncInverseTime,
        ShopForm::AlwaysTcp,
        ShopForm::SpacedWords,
        ShopForm::Variables,
    ];
    /// File stem and extension.
    pub fn file_name(self, stem: &str) -> String {
        match self {
            ShopForm::ConversationalFunctionTcpm => format!("{stem}-conv-function-tcpm.H"),
            ShopForm::ConversationalM128 => format!("{stem}-conv-m128.H"),
            ShopForm::FanucInverseTime => format!("{stem}-fanuc-g93.nc"),
            ShopForm::LinuxCncInverseTime => format!("{stem}-linuxcnc-g93-m428.ngc"),
            ShopForm::AlwaysTcp => format!("{stem}-always-tcp.ngc"),
            ShopForm::SpacedWords => format!("{stem}-spaced-words.nc"),
            ShopForm::Variables => format!("{stem}-variables.nc"),
        }
    }
}

/// The pass of the shop-form fixtures: A-C, 0.5 mm spacing, F2000 (domain rule or
/// continuous branch, `pole_distance_deg` from the pole).
pub fn shop_pass(domain_rule: bool, pole_distance_deg: f64) -> Pass {
    Pass {
        pole_distance_deg,
        domain_rule,
        spacing_mm: 0.5,
        ..Pass::default()
    }
}

/// The program text of a pass in a shop form, named `name`. The pass's tool-tip path and
/// joint values are those of [`program`]; under G93 each block's F is its length divided by
/// the programmed feed's time, written with 3 decimals (1/min).
pub fn shop_program(p: &Pass, form: ShopForm, name: &str) -> String {
    let j = joints(p);
    let pl = if p.b_axis { 'B' } else { 'A' };
    let d = p.rotary_decimals;
    let f = num(p.feed_mm_min, 0, false);
    let mut out = String::new();
    let mut line = |s: String| {
        out.push_str(&s);
        out.push('\n');
    };
    let block_f = |k: usize| {
        let a = j[k - 1];
        let b = j[k];
        let len = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
        format!("{:.3}", p.feed_mm_min / len)
    };
    match form {
        ShopForm::ConversationalFunctionTcpm | ShopForm::ConversationalM128 => {
            let fn_tcpm = form == ShopForm::ConversationalFunctionTcpm;
            let mut n = 0;
            let mut blk = |s: String, line: &mut dyn FnMut(String)| {
                line(format!("{n} {s}"));
                n += 1;
            };
            blk(format!("BEGIN PGM {name} MM"), &mut line);
            blk("BLK FORM 0.1 Z  X-10  Y-20  Z-30".into(), &mut line);
            blk(
                format!(
                    "BLK FORM 0.2  X+{}  Y+20  Z+0",
                    num(p.length_mm + 10.0, 0, false)
                ),
                &mut line,
            );
            blk("TOOL CALL 1 Z S12000".into(), &mut line);
            blk("L  Z+100 R0 FMAX M3".into(), &mut line);
            blk(
                if fn_tcpm {
                    "FUNCTION TCPM F TCP AXIS POS PATHCTRL AXIS".into()
                } else {
                    "L  M128".into()
                },
                &mut line,
            );
            let q0 = j[0];
            blk(
                format!(
                    "L  X{}  Y{}  {pl}{}  C{} R0 FMAX",
                    num(q0[0], 3, true),
                    num(q0[1], 3, true),
                    num(q0[3], d, true),
                    num(q0[4], d, true)
                ),
                &mut line,
            );
            blk(
                format!("L  Z{} R0 FMAX M8", num(q0[2] + 5.0, 3, true)),
                &mut line,
            );
            // The plunge at its own feed: the pass is a run of its own from its first point.
            blk(format!("L  Z{} R0 F500", num(q0[2], 3, true)), &mut line);
            blk("* - PASS".into(), &mut line);
            for (k, q) in j.iter().enumerate().skip(1) {
                let feed = if k == 1 {
                    format!(" F{f}")
                } else {
                    String::new()
                };
                blk(
                    format!(
                        "L  X{}  Y{}  Z{}  {pl}{}  C{}{feed}",
                        num(q[0], 3, true),
                        num(q[1], 3, true),
                        num(q[2], 3, true),
                        num(q[3], d, true),
                        num(q[4], d, true),
                    ),
                    &mut line,
                );
            }
            blk("L  Z+100 R0 FMAX M9".into(), &mut line);
            blk(
                if fn_tcpm {
                    "FUNCTION RESET TCPM".into()
                } else {
                    "L  M129".into()
                },
                &mut line,
            );
            blk("L  M30".into(), &mut line);
            blk(format!("END PGM {name} MM"), &mut line);
        }
        ShopForm::FanucInverseTime
        | ShopForm::LinuxCncInverseTime
        | ShopForm::AlwaysTcp
        | ShopForm::SpacedWords
        | ShopForm::Variables => {
            let linuxcnc = matches!(form, ShopForm::LinuxCncInverseTime | ShopForm::AlwaysTcp);
            let g93 = matches!(
                form,
                ShopForm::FanucInverseTime | ShopForm::LinuxCncInverseTime
            );
            let spaced = matches!(form, ShopForm::LinuxCncInverseTime | ShopForm::SpacedWords);
            let w = |l: char, v: String| {
                if spaced {
                    format!("{l} {v}")
                } else {
                    format!("{l}{v}")
                }
            };
            if !linuxcnc {
                line("%".into());
                line("O1000".into());
            }
            line(format!("({name})"));
            line("G90 G21 G94 G17".into());
            line("T1 M6".into());
            line("S12000 M3".into());
            match form {
                ShopForm::LinuxCncInverseTime => line("M428 (TCP KINEMATICS)".into()),
                ShopForm::AlwaysTcp => {}
                _ => line("G43.4 H1".into()),
            }
            let q0 = j[0];
            if form == ShopForm::Variables {
                // A first run whose rotary words are variables: carried through, listed.
                line(format!("#101={}", num(q0[3] + 10.0, d, false)));
                line(format!("#102={}", num(q0[4], d, false)));
                line(format!("G0 X{} Y10. Z0. A#101 C#102", num(q0[0], 3, false)));
                line(format!("G1 X{} Y10. Z-5. F{f}", num(q0[0] + 1.0, 3, false)));
                line(format!("X{} A#101 C[#102+1.]", num(q0[0] + 2.0, 3, false)));
                line(format!("X{} A#101 C[#102+2.]", num(q0[0] + 3.0, 3, false)));
                line("G0 Z50.".into());
            }
            line(format!(
                "G0 {} {} {} {}",
                w('X', num(q0[0], 3, false)),
                w('Y', num(q0[1], 3, false)),
                w(pl, num(q0[3], d, false)),
                w('C', num(q0[4], d, false))
            ));
            line(format!("G0 {}", w('Z', num(q0[2] + 5.0, 3, false))));
            // The plunge at its own feed: the pass is a run of its own from its first point.
            line(format!("G1 {} F500", w('Z', num(q0[2], 3, false))));
            if g93 {
                line("G93".into());
            }
            for (k, q) in j.iter().enumerate().skip(1) {
                let mut s = format!(
                    "{} {} {} {} {}",
                    w('X', num(q[0], 3, false)),
                    w('Y', num(q[1], 3, false)),
                    w('Z', num(q[2], 3, false)),
                    w(pl, num(q[3], d, false)),
                    w('C', num(q[4], d, false))
                );
                if g93 {
                    s.push_str(&format!(" F{}", block_f(k)));
                } else if k == 1 {
                    s.push_str(&format!(" F{f}"));
                }
                line(s);
            }
            if g93 {
                line("G94".into());
            }
            line(format!("G0 {}", w('Z', "50.".into())));
            match form {
                ShopForm::LinuxCncInverseTime => line("M429 (IDENTITY KINEMATICS)".into()),
                ShopForm::AlwaysTcp => {}
                _ => line("G49".into()),
            }
            line(if linuxcnc { "M2".into() } else { "M30".into() });
            if !linuxcnc {
                line("%".into());
            }
        }
    }
    out
}

/// A zigzag finishing program in Heidenhain ISO: `passes` parallel passes (alternating
/// direction, 2 mm apart in Y), each its own G1 run between rapid moves, the k-th passing
/// at `pole_distances_deg[k % len]` from the pole — a program with many singular zones.
pub fn zigzag_program(
    base: &Pass,
    passes: usize,
    pole_distances_deg: &[f64],
    name: &str,
) -> String {
    let pl = if base.b_axis { 'B' } else { 'A' };
    let d = base.rotary_decimals;
    let mut out = format!("%{name} G71 *\n");
    let mut n = 10;
    let mut line = |s: String| {
        let _ = writeln!(out, "N{n} {s} *");
        n += 10;
    };
    line("G90".into());
    line("T1 M6".into());
    line("S12000 M3".into());
    line("M128".into());
    for k in 0..passes {
        let pass = Pass {
            pole_distance_deg: pole_distances_deg[k % pole_distances_deg.len().max(1)],
            ..base.clone()
        };
        let mut j = joints(&pass);
        if k % 2 == 1 {
            j.reverse();
        }
        let y = 2.0 * k as f64;
        let q0 = j[0];
        line(format!(
            "G00 X{} Y{} Z+10 {pl}{} C{}",
            num(q0[0], 3, true),
            num(y, 3, true),
            num(q0[3], d, true),
            num(q0[4], d, true)
        ));
        line(format!(
            "G01 Z{} F{}",
            num(q0[2], 3, true),
            num(base.feed_mm_min, 0, false)
        ));
        for q in &j[1..] {
            line(format!(
                "X{} Y{} Z{} {pl}{} C{}",
                num(q[0], 3, true),
                num(y, 3, true),
                num(q[2], 3, true),
                num(q[3], d, true),
                num(q[4], d, true)
            ));
        }
        line("G00 Z+10".into());
    }
    line("M129".into());
    line("M30".into());
    line(format!("%{name} G71"));
    out
}

/// Every NC program under `dir` (recursively, by extension: `.I` `.H` `.mpf` `.MPF` `.nc`
/// `.NC` `.ngc` `.tap`), sorted — the fixture list the test suites share.
///
/// # Panics
/// If a folder under `dir` cannot be read.
pub fn nc_files(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read a fixture folder") {
            let p = e.expect("read a fixture folder entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if matches!(
                p.extension().and_then(|x| x.to_str()),
                Some("I" | "H" | "mpf" | "MPF" | "nc" | "NC" | "ngc" | "tap")
            ) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}
