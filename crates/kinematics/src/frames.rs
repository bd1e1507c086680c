//! Machine frame ↔ part frame through the kinematic chain ([`Chain`]: where the rotary axes
//! sit): machine-frame X Y Z (what the linear axes do) and the tool tip in the part frame
//! converted into each other for given primary and C angles.
//!
//! Frames and conventions (all lengths mm, machine frame = the linear axes' frame; the axis
//! directions, senses and the order part → pole axis → tilting axis → tool are those of
//! [`crate::rotary`]):
//!
//! - A **table** axis turns the part by `−s·θ` (sense `s`, ISO 841) about the line through
//!   its point `q` along its direction `u` (both at zero, machine coordinates): a part point
//!   `x` goes to `g(x) = q + R(u, −s·θ)·(x − q)`. On a table-table machine the pole axis (C)
//!   rides on the tilting one, so a part point goes to `g_P(g_C(x))`.
//! - A **head** axis turns the tool by `+s·θ` about the line through its point; a head
//!   axis' point is given relative to the spindle gauge point (where tool lengths are
//!   measured from) with every axis at zero. The linear axes carry the head: X Y Z place
//!   the tool tip as if the head axes were at zero (the controller's tool-length
//!   compensation along the tool direction at zero), and turning the head moves the tip by
//!   `offset(θ) = h_outer(h_inner(tip₀)) − tip₀`, independent of where the linear axes are
//!   (the axis lines move with them). With `L` the tool length and `t0` the tool direction
//!   at zero (tip → spindle), a head axis passes through `tip₀ + point + L·t0`.
//! - `d` is the work offset (datum): the machine coordinates of the program's zero. The
//!   part's zero sits at `d` when every axis is at zero (how a post sets up a job without
//!   TCPM), and the part's axes are then the machine's.
//!
//! For the built-in form (table-table, C along Z carried by A along X or B along Y) a part
//! point `x_W` is at, in machine coordinates,
//!
//! ```text
//! x_M = p + Rp(−sp·P) · ( (c − p) + Rz(−sc·C) · (d + x_W − c) )
//! ```
//!
//! (`p` a point on the primary axis line, `c` a point on the C axis at P = 0; the axes need
//! not intersect) and the program's X Y Z without TCPM are `x_M − d − offset(θ)` (no head:
//! offset 0). Inversely `x_W = Rz(sc·C) · ( Rp(sp·P)·(x_M − p) − (c − p) ) + c − d`. With
//! `p = c = d = 0` this is C17's eq. 1, `P_M = Rx(−A)·Rz(−C)·P_W` (its senses).

use crate::chain::Chain;
use crate::machine::Machine;
use crate::rotary::{Carrier, RotaryAxis, rotate_deg};
use crate::vec3::{add, scale, sub};

/// A table axis turning `v` (a vector, no position): `R(u, −s·θ)·v`.
fn table_turn(axis: &RotaryAxis, sense: f64, angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
    rotate_deg(axis.direction, -sense * angle_deg, v)
}

impl Chain {
    /// A part-frame vector (a direction, no position) in the machine frame: the table axes'
    /// rotation of it (`Q·v_W`; the identity on a head-head machine). On a table-table
    /// machine `Q·o_wp` is the tool direction at zero.
    pub fn part_vector_in_machine(
        machine: &Machine,
        p_deg: f64,
        c_deg: f64,
        v_w: [f64; 3],
    ) -> [f64; 3] {
        let r = &machine.rotary;
        let mut v = v_w;
        if r.c.carrier == Carrier::Table {
            v = table_turn(&r.c, machine.c_sense, c_deg, v);
        }
        if r.primary.carrier == Carrier::Table {
            v = table_turn(&r.primary, machine.primary_sense, p_deg, v);
        }
        v
    }

    /// The displacement of the tool tip by the head axes at (`p_deg`, `c_deg`), mm,
    /// machine frame, for a tool of length `tool_length_mm` (module docs); zero on a
    /// table-table machine.
    pub fn head_offset_mm(
        &self,
        machine: &Machine,
        p_deg: f64,
        c_deg: f64,
        tool_length_mm: f64,
    ) -> [f64; 3] {
        let r = &machine.rotary;
        let reach = scale(r.tool_direction, tool_length_mm);
        // Relative to the tip at zero: h(y) = Q + R(u, s·θ)·(y − Q), applied to y = 0.
        let turn = |axis: &RotaryAxis, point: [f64; 3], sense: f64, angle: f64, y: [f64; 3]| {
            let q = add(point, reach);
            add(q, rotate_deg(axis.direction, sense * angle, sub(y, q)))
        };
        let mut tip = [0.0; 3];
        if r.primary.carrier == Carrier::Head {
            tip = turn(
                &r.primary,
                self.primary_axis_point_mm,
                machine.primary_sense,
                p_deg,
                tip,
            );
        }
        if r.c.carrier == Carrier::Head {
            tip = turn(&r.c, self.c_axis_point_mm, machine.c_sense, c_deg, tip);
        }
        tip
    }

    /// The machine coordinates of the part point `x` (`d + x_W`) turned by the table axes.
    fn table_to_machine(&self, machine: &Machine, p_deg: f64, c_deg: f64, x: [f64; 3]) -> [f64; 3] {
        let r = &machine.rotary;
        let p = self.primary_axis_point_mm;
        let c = self.c_axis_point_mm;
        match (r.c.carrier, r.primary.carrier) {
            (Carrier::Table, Carrier::Table) => {
                let on_table = table_turn(&r.c, machine.c_sense, c_deg, sub(x, c));
                let on_cradle = add(sub(c, p), on_table);
                add(
                    p,
                    table_turn(&r.primary, machine.primary_sense, p_deg, on_cradle),
                )
            }
            (Carrier::Table, Carrier::Head) => {
                add(c, table_turn(&r.c, machine.c_sense, c_deg, sub(x, c)))
            }
            _ => x,
        }
    }

    /// The inverse of `table_to_machine`.
    fn machine_to_table(
        &self,
        machine: &Machine,
        p_deg: f64,
        c_deg: f64,
        x_m: [f64; 3],
    ) -> [f64; 3] {
        let r = &machine.rotary;
        let p = self.primary_axis_point_mm;
        let c = self.c_axis_point_mm;
        match (r.c.carrier, r.primary.carrier) {
            (Carrier::Table, Carrier::Table) => {
                let on_cradle = table_turn(&r.primary, machine.primary_sense, -p_deg, sub(x_m, p));
                let on_table = table_turn(&r.c, machine.c_sense, -c_deg, sub(on_cradle, sub(c, p)));
                add(on_table, c)
            }
            (Carrier::Table, Carrier::Head) => {
                add(table_turn(&r.c, machine.c_sense, -c_deg, sub(x_m, c)), c)
            }
            _ => x_m,
        }
    }

    /// The program's X Y Z without TCPM (machine coordinates minus the work offset
    /// `datum_mm`) that put the tool tip at `tip_part_mm` (part coordinates) with the
    /// rotary axes at `p_deg`, `c_deg`. On a machine with a head axis this is for a tool of
    /// length 0 ([`Chain::program_xyz_for_tool`]).
    pub fn program_xyz(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        tip_part_mm: [f64; 3],
    ) -> [f64; 3] {
        self.program_xyz_for_tool(machine, datum_mm, p_deg, c_deg, tip_part_mm, 0.0)
    }

    /// [`Chain::program_xyz`] for a tool of length `tool_length_mm` (it matters only where
    /// a head axis turns the tool).
    pub fn program_xyz_for_tool(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        tip_part_mm: [f64; 3],
        tool_length_mm: f64,
    ) -> [f64; 3] {
        let x_m = self.table_to_machine(machine, p_deg, c_deg, add(datum_mm, tip_part_mm));
        let x_m = if machine.layout() == crate::rotary::Layout::TableTable {
            x_m
        } else {
            sub(
                x_m,
                self.head_offset_mm(machine, p_deg, c_deg, tool_length_mm),
            )
        };
        sub(x_m, datum_mm)
    }

    /// The tool tip in part coordinates for the program's X Y Z without TCPM
    /// (`program_mm`, machine coordinates minus `datum_mm`) at `p_deg`, `c_deg`: the
    /// inverse of [`Chain::program_xyz`] (a tool of length 0 where a head axis turns it).
    pub fn part_tip(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        program_mm: [f64; 3],
    ) -> [f64; 3] {
        self.part_tip_for_tool(machine, datum_mm, p_deg, c_deg, program_mm, 0.0)
    }

    /// [`Chain::part_tip`] for a tool of length `tool_length_mm`.
    pub fn part_tip_for_tool(
        &self,
        machine: &Machine,
        datum_mm: [f64; 3],
        p_deg: f64,
        c_deg: f64,
        program_mm: [f64; 3],
        tool_length_mm: f64,
    ) -> [f64; 3] {
        let x_m = add(program_mm, datum_mm);
        let x_m = if machine.layout() == crate::rotary::Layout::TableTable {
            x_m
        } else {
            add(
                x_m,
                self.head_offset_mm(machine, p_deg, c_deg, tool_length_mm),
            )
        };
        sub(self.machine_to_table(machine, p_deg, c_deg, x_m), datum_mm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::forward;

    fn machines() -> Vec<Machine> {
        let mut out = Vec::new();
        for name in Machine::builtin_names() {
            let m = Machine::builtin(name).unwrap();
            for (sp, sc) in [(1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0)] {
                out.push(Machine {
                    primary_sense: sp,
                    c_sense: sc,
                    ..m.clone()
                });
            }
        }
        out
    }

    const CHAIN: Chain = Chain {
        primary_axis_point_mm: [3.0, -20.0, -150.0],
        c_axis_point_mm: [12.5, -7.0, -140.0],
    };
    const DATUM: [f64; 3] = [-30.489, -4.3, 38.054];

    fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() <= tol)
    }

    /// Angles including the pole, C at ±180° and beyond a turn.
    const ANGLES: [(f64, f64); 8] = [
        (0.0, 0.0),
        (0.0, 180.0),
        (1e-9, -180.0),
        (23.162, 333.802),
        (-45.0, 90.0),
        (90.0, -720.5),
        (-100.0, 12.0),
        (5.0, 1e6),
    ];

    #[test]
    fn part_tip_inverts_program_xyz() {
        for m in machines() {
            for (p, c) in ANGLES {
                for tip in [[0.0, 0.0, 0.0], [25.0, 0.0, -8.0], [-50.0, 70.0, 100.0]] {
                    let x = CHAIN.program_xyz(&m, DATUM, p, c, tip);
                    let back = CHAIN.part_tip(&m, DATUM, p, c, x);
                    assert!(close(back, tip, 1e-9), "{p} {c} {tip:?} → {back:?}");
                }
            }
        }
    }

    /// The tool axis (machine ẑ) seen from the part is `forward(P, C)`: moving the
    /// program point along machine ẑ moves the part-frame tip along o_wp.
    #[test]
    fn the_machine_z_axis_is_the_tool_axis_of_forward() {
        for m in machines() {
            for (p, c) in ANGLES {
                let x = [10.0, -3.0, 40.0];
                let a = CHAIN.part_tip(&m, DATUM, p, c, x);
                let b = CHAIN.part_tip(&m, DATUM, p, c, [x[0], x[1], x[2] + 1.0]);
                let o = forward(&m, p, c);
                assert!(close(sub(b, a), o, 1e-9), "{p} {c}");
                let q = Chain::part_vector_in_machine(&m, p, c, o);
                assert!(close(q, [0.0, 0.0, 1.0], 1e-12), "{q:?}");
            }
        }
    }

    /// C17 eq. 1 (axes intersecting at the origin, no datum): P_M = Rx(−A)·Rz(−C)·P_W with
    /// C17's senses.
    #[test]
    fn c17_equation_1_is_the_special_case() {
        let m = Machine {
            primary_sense: 1.0,
            c_sense: 1.0,
            ..Machine::builtin("mikron-ucp710").unwrap()
        };
        let (a, c) = (30.0f64, 60.0f64);
        let pw = [10.0, 20.0, 5.0];
        let got = Chain::AT_ORIGIN.program_xyz(&m, [0.0; 3], a, c, pw);
        // Rz(−C) then Rx(−A), written out.
        let (sc, cc) = (-c).to_radians().sin_cos();
        let r1 = [cc * pw[0] - sc * pw[1], sc * pw[0] + cc * pw[1], pw[2]];
        let (sa, ca) = (-a).to_radians().sin_cos();
        let r2 = [r1[0], ca * r1[1] - sa * r1[2], sa * r1[1] + ca * r1[2]];
        assert!(close(got, r2, 1e-12), "{got:?} vs {r2:?}");
    }

    /// A point on the C axis does not move when C turns; at the pole C turns the table
    /// about the tool axis, so the tool tip on the C axis is fixed for any C.
    #[test]
    fn points_on_the_axes_stay_put() {
        for m in machines() {
            // The part point that sits on the C axis at P = 0.
            let on_c = sub(sub(CHAIN.c_axis_point_mm, DATUM), [0.0, 0.0, 5.0]);
            let x0 = CHAIN.program_xyz(&m, DATUM, 0.0, 0.0, on_c);
            for c in [-180.0, -33.0, 180.0, 540.0] {
                let x = CHAIN.program_xyz(&m, DATUM, 0.0, c, on_c);
                assert!(close(x, x0, 1e-9), "{c}");
            }
        }
    }

    /// 50 mm off the C axis at the pole, 192 rpm on C moves the linear axes at
    /// 2π·50·192/60 mm/s ≈ 60.3 m/min (C17 eq. 6): finite differences of program_xyz.
    #[test]
    fn linear_axes_follow_the_table() {
        let m = Machine::builtin("mikron-ucp710").unwrap();
        let tip = sub(add(CHAIN.c_axis_point_mm, [50.0, 0.0, 0.0]), DATUM);
        let dc_deg = 1e-4;
        let a = CHAIN.program_xyz(&m, DATUM, 0.0, 10.0, tip);
        let b = CHAIN.program_xyz(&m, DATUM, 0.0, 10.0 + dc_deg, tip);
        let mm_per_deg = sub(b, a).iter().map(|v| v * v).sum::<f64>().sqrt() / dc_deg;
        let m_min = mm_per_deg * 192.0 * 360.0 / 1000.0;
        assert!((m_min - 60.32).abs() < 0.01, "{m_min}");
    }

    /// The formulas this module had for the built-in form, kept here as written: the
    /// general code must give the same bits for every table-table A-C and B-C machine.
    mod before {
        use crate::machine::{Machine, PrimaryAxis};
        use crate::vec3::{add, sub};

        fn rot_p(primary: PrimaryAxis, angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
            let (s, c) = angle_deg.to_radians().sin_cos();
            match primary {
                PrimaryAxis::A => [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]],
                PrimaryAxis::B => [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]],
            }
        }
        fn rot_z(angle_deg: f64, v: [f64; 3]) -> [f64; 3] {
            let (s, c) = angle_deg.to_radians().sin_cos();
            [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
        }
        fn kind(m: &Machine) -> PrimaryAxis {
            m.standard_form().unwrap().primary
        }
        pub fn program_xyz(
            chain: &super::Chain,
            m: &Machine,
            datum: [f64; 3],
            p_deg: f64,
            c_deg: f64,
            tip: [f64; 3],
        ) -> [f64; 3] {
            let p = chain.primary_axis_point_mm;
            let c = chain.c_axis_point_mm;
            let on_table = rot_z(-m.c_sense * c_deg, sub(add(datum, tip), c));
            let on_cradle = add(sub(c, p), on_table);
            let x_m = add(p, rot_p(kind(m), -m.primary_sense * p_deg, on_cradle));
            sub(x_m, datum)
        }
        pub fn part_tip(
            chain: &super::Chain,
            m: &Machine,
            datum: [f64; 3],
            p_deg: f64,
            c_deg: f64,
            program: [f64; 3],
        ) -> [f64; 3] {
            let p = chain.primary_axis_point_mm;
            let c = chain.c_axis_point_mm;
            let x_m = add(program, datum);
            let on_cradle = rot_p(kind(m), m.primary_sense * p_deg, sub(x_m, p));
            let on_table = rot_z(m.c_sense * c_deg, sub(on_cradle, sub(c, p)));
            sub(add(on_table, c), datum)
        }
        pub fn part_vector_in_machine(
            m: &Machine,
            p_deg: f64,
            c_deg: f64,
            v: [f64; 3],
        ) -> [f64; 3] {
            rot_p(
                kind(m),
                -m.primary_sense * p_deg,
                rot_z(-m.c_sense * c_deg, v),
            )
        }
    }

    /// Regression: the general chain gives the built-in form's values bit for bit.
    #[test]
    fn the_builtin_form_is_computed_bit_for_bit_as_before() {
        let mut rng = crate::testutil::SplitMix64(3);
        for m in machines() {
            for n in 0..2000 {
                let (p, c) = ANGLES
                    .get(n)
                    .copied()
                    .unwrap_or_else(|| (rng.uniform(-120.0, 120.0), rng.uniform(-720.0, 720.0)));
                let tip = [
                    rng.uniform(-200.0, 200.0),
                    rng.uniform(-200.0, 200.0),
                    rng.uniform(-200.0, 200.0),
                ];
                let x = CHAIN.program_xyz(&m, DATUM, p, c, tip);
                assert_eq!(x, before::program_xyz(&CHAIN, &m, DATUM, p, c, tip));
                assert_eq!(
                    CHAIN.part_tip(&m, DATUM, p, c, x),
                    before::part_tip(&CHAIN, &m, DATUM, p, c, x)
                );
                assert_eq!(
                    Chain::part_vector_in_machine(&m, p, c, tip),
                    before::part_vector_in_machine(&m, p, c, tip)
                );
            }
        }
    }

    /// Physical reference for every layout, written from the rigid motions: the table
    /// axes turn the part about their lines, the head axes turn the tool about theirs; the
    /// tool tip must land on the part point, and the tool direction seen from the part must
    /// be [`forward`].
    #[test]
    fn every_layout_puts_the_tool_tip_on_the_part_point_along_forward() {
        use crate::rotary::{Carrier, rotate_deg};
        let examples = crate::machine_file::tests::EXAMPLES;
        let mut rng = crate::testutil::SplitMix64(8);
        for (name, text) in examples {
            let mut m = Machine::from_toml_str(text, name).unwrap();
            let chain = Chain {
                primary_axis_point_mm: [12.0, -30.0, 140.0],
                c_axis_point_mm: [-40.0, 25.0, -80.0],
            };
            m.chain = Some(chain);
            let r = m.rotary;
            for _ in 0..200 {
                let (p, c) = (rng.uniform(-90.0, 90.0), rng.uniform(-360.0, 360.0));
                let tool_mm = rng.uniform(0.0, 150.0);
                let tip = [
                    rng.uniform(-100.0, 100.0),
                    rng.uniform(-100.0, 100.0),
                    rng.uniform(-50.0, 50.0),
                ];
                let x = chain.program_xyz_for_tool(&m, DATUM, p, c, tip, tool_mm);
                let back = chain.part_tip_for_tool(&m, DATUM, p, c, x, tool_mm);
                assert!(close(back, tip, 1e-9), "{name}");
                // The part point in the machine: table axes about their lines, the one next
                // to the part first (physical angle −s·θ).
                let turn = |q: [f64; 3], u, s: f64, th: f64, v: [f64; 3]| {
                    add(q, rotate_deg(u, -s * th, sub(v, q)))
                };
                let mut part = add(DATUM, tip);
                let mut tool = r.tool_direction;
                if r.c.carrier == Carrier::Table {
                    part = turn(chain.c_axis_point_mm, r.c.direction, m.c_sense, c, part);
                }
                if r.primary.carrier == Carrier::Table {
                    part = turn(
                        chain.primary_axis_point_mm,
                        r.primary.direction,
                        m.primary_sense,
                        p,
                        part,
                    );
                }
                // The tool tip: the linear axes at x + d place the tip as if the head were at
                // zero; the gauge point is tool_mm up the tool; head axes (points relative
                // to the gauge point) turn the tool, the one next to the tool first.
                let tip0 = add(x, DATUM);
                let gauge = add(tip0, scale(r.tool_direction, tool_mm));
                let mut tool_tip = tip0;
                if r.primary.carrier == Carrier::Head {
                    let q = add(gauge, chain.primary_axis_point_mm);
                    tool_tip = turn(q, r.primary.direction, -m.primary_sense, p, tool_tip);
                    tool = rotate_deg(r.primary.direction, m.primary_sense * p, tool);
                }
                if r.c.carrier == Carrier::Head {
                    let q = add(gauge, chain.c_axis_point_mm);
                    tool_tip = turn(q, r.c.direction, -m.c_sense, c, tool_tip);
                    tool = rotate_deg(r.c.direction, m.c_sense * c, tool);
                }
                assert!(
                    close(tool_tip, part, 1e-9),
                    "{name}: {tool_tip:?} vs {part:?}"
                );
                // The tool direction seen from the part: undo the table turns.
                let mut seen = tool;
                if r.primary.carrier == Carrier::Table {
                    seen = rotate_deg(r.primary.direction, m.primary_sense * p, seen);
                }
                if r.c.carrier == Carrier::Table {
                    seen = rotate_deg(r.c.direction, m.c_sense * c, seen);
                }
                assert!(close(seen, forward(&m, p, c), 1e-12), "{name}");
            }
        }
    }

    /// On a head machine the tip moves with the head by the pivot arm: a B head with its
    /// pivot 150 mm above the gauge point and a 50 mm tool, turned 90°, puts the tip 200 mm
    /// sideways and 200 mm up (the arm is 200 mm).
    #[test]
    fn a_head_axis_swings_the_tip_about_its_pivot() {
        let m = crate::machine_file::tests::example("example-head-table-bc");
        let chain = m.chain.unwrap();
        assert_eq!(chain.primary_axis_point_mm, [0.0, 0.0, 150.0]);
        let off = chain.head_offset_mm(&m, 90.0, 0.0, 50.0);
        // +B turns the tool right-handed about +Y: the tool axis goes to +X, so the tip,
        // 200 mm below the pivot, goes to −X of it.
        assert!(close(off, [-200.0, 0.0, 200.0], 1e-12), "{off:?}");
        assert!(close(
            chain.head_offset_mm(&m, 0.0, 33.0, 50.0),
            [0.0; 3],
            0.0
        ));
    }
}
