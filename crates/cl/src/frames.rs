//! The coordinate-frame records of APT CL files: what frame the values after them are in,
//! as the CAM systems that write them mean it. polepatch posts the values in one frame,
//! the frame the CL values are written in (the program zero); a record that would put
//! the values after it in another frame, or whose frame cannot be told from the file, is
//! refused by name with its line and column — never read as a rotated or moved part.
//!
//! - `TRNTYP/WORLD,0,0,0` (CAMWorks): the values that follow are world coordinates.
//!   Another `TRNTYP` is refused.
//! - `CSYS/r11,r12,r13,t1, r21,r22,r23,t2, r31,r32,r33,t3` (CAMWorks, after
//!   `TRNTYP/WORLD`): the setup's frame, a 3×4 matrix by rows. It does **not** transform
//!   the values: CAMWorks writes every `GOTO`, `CIRCLE`, … in world coordinates, with the
//!   world tool axis. What it gives is the setup's tool axis, its third column
//!   `(r13, r23, r33)`, the tool axis of the 3-value `GOTO`s that follow. A `CSYS` other
//!   than the identity with no `TRNTYP/WORLD` before it is refused (the frame of the values
//!   is then not stated); R must be a rotation.
//! - `MSYS/x0,y0,z0, xi,xj,xk, yi,yj,yk` (NX CLSF): the machine coordinate system (MCS):
//!   its origin and X and Y axes in NX's absolute frame. NX writes the `GOTO`s in the MCS,
//!   so the values are posted as they are whatever the MCS is; a later `MSYS` naming
//!   another MCS (the values after it in another frame: a work offset change polepatch does
//!   not write) is refused, as is a first `MSYS` other than the identity after moves.
//! - `TRACUT`, `INDEX`, `COPY`, `REFSYS`, `TRANS`, `ORIGIN`: refused by name. `TRACUT`
//!   transforms the cutter locations after it, or — as some CAM systems pass it on —
//!   states the transformation already applied, and the file does not say which;
//!   `INDEX`…`COPY` repeat the records between them transformed; `REFSYS` sets the frame
//!   the values are given in; `TRANS` and `ORIGIN` move the program zero.
//!
//! Where each meaning comes from is in `docs/post.md` ("Coordinate frames").

use crate::records::At;
use crate::values::{coordinate, number};
use crate::{ClError, err};
use polepatch_kinematics::vec3;

use crate::tolerances::CSYS_IDENTITY_TOLERANCE;
pub use crate::tolerances::{FRAME_TOLERANCE, MSYS_AXIS_TOLERANCE, MSYS_ORIGIN_TOLERANCE_MM};

/// An NX machine coordinate system: origin (mm) and X and Y axes, in NX's absolute frame.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Mcs {
    origin_mm: [f64; 3],
    x: [f64; 3],
    y: [f64; 3],
}

impl Mcs {
    const IDENTITY: Mcs = Mcs {
        origin_mm: [0.0; 3],
        x: [1.0, 0.0, 0.0],
        y: [0.0, 1.0, 0.0],
    };

    fn same(&self, o: &Mcs) -> bool {
        let close = |a: [f64; 3], b: [f64; 3], tol: f64| (0..3).all(|i| (a[i] - b[i]).abs() <= tol);
        close(self.origin_mm, o.origin_mm, MSYS_ORIGIN_TOLERANCE_MM)
            && close(self.x, o.x, MSYS_AXIS_TOLERANCE)
            && close(self.y, o.y, MSYS_AXIS_TOLERANCE)
    }
}

/// The frame records read so far.
#[derive(Debug, Default)]
pub(crate) struct Frames {
    /// Where `TRNTYP/WORLD,0,0,0` was read (it stays in force).
    world: Option<At>,
    /// The MCS the values are in (the first `MSYS`, or the identity when moves came
    /// first), and where it was set.
    mcs: Option<(Mcs, At)>,
}

fn e(at: At, message: impl Into<String>) -> ClError {
    err(at.line, at.column, message)
}

/// The numbers of a frame record, each at its column.
fn numbers<const N: usize>(word: &str, f: &[(&str, At)], at: At) -> Result<[f64; N], ClError> {
    if f.len() != N {
        return Err(e(
            f.first().map_or(at, |x| x.1),
            format!("{word} needs {N} values; got {}", f.len()),
        ));
    }
    let mut v = [0.0; N];
    for (i, &(t, a)) in f.iter().enumerate() {
        v[i] = number(t, a, &format!("{word} value"))?;
    }
    Ok(v)
}

fn orthonormal(rows: &[[f64; 3]]) -> bool {
    rows.iter().enumerate().all(|(i, a)| {
        rows.iter().enumerate().all(|(j, b)| {
            let want = if i == j { 1.0 } else { 0.0 };
            (vec3::dot(*a, *b) - want).abs() <= FRAME_TOLERANCE
        })
    })
}

fn fmt3(v: [f64; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}

impl Frames {
    /// `TRNTYP/WORLD,0,0,0`: the values that follow are world coordinates; any other
    /// `TRNTYP` is refused.
    pub(crate) fn trntyp(&mut self, f: &[(&str, At)], at: At) -> Result<(), ClError> {
        let world = matches!(f.first(), Some((w, _)) if w.eq_ignore_ascii_case("WORLD"))
            && f.len() == 4
            && f[1..]
                .iter()
                .all(|&(t, _)| t.parse::<f64>().is_ok_and(|v| v == 0.0));
        if !world {
            return Err(e(
                at,
                "TRNTYP other than WORLD,0,0,0 is not posted (the values after it would not be world coordinates, and in which frame they are is not stated); give --ignore TRNTYP only if the values are in the frame the program is run in",
            )
            .refusing("TRNTYP"));
        }
        self.world = Some(at);
        Ok(())
    }

    /// `CSYS/[R|t]` by rows (`scale`: mm per file unit): the setup's tool axis, R's third
    /// column, for the 3-value `GOTO`s that follow. Nothing is transformed (module docs).
    pub(crate) fn csys(
        &mut self,
        f: &[(&str, At)],
        at: At,
        scale: f64,
    ) -> Result<[f64; 3], ClError> {
        let v: [f64; 12] = numbers("CSYS (a 3×4 matrix [R|t] by rows)", f, at)?;
        let r = [[v[0], v[1], v[2]], [v[4], v[5], v[6]], [v[8], v[9], v[10]]];
        let det = vec3::dot(r[0], vec3::cross(r[1], r[2]));
        if !orthonormal(&r) || det <= 0.0 {
            return Err(e(
                at,
                "CSYS: the matrix is not a rotation (orthonormal, right-handed): refused",
            ));
        }
        for i in [3, 7, 11] {
            coordinate(v[i] * scale, f[i].1, "CSYS origin", f[i].0)?;
        }
        let identity = (0..3).all(|i| {
            (0..3).all(|j| {
                (r[i][j] - if i == j { 1.0 } else { 0.0 }).abs() <= CSYS_IDENTITY_TOLERANCE
            })
        }) && [3, 7, 11].iter().all(|&i| v[i] == 0.0);
        let axis = [r[0][2], r[1][2], r[2][2]];
        if !identity && self.world.is_none() {
            return Err(e(
                at,
                format!(
                    "CSYS other than the identity (setup tool axis {}) without TRNTYP/WORLD before it: whether the values after it are world coordinates (CAMWorks writes TRNTYP/WORLD,0,0,0 before each CSYS, and its GOTOs are then in the world frame) or in the CSYS frame is not stated: refused",
                    fmt3(axis)
                ),
            ));
        }
        let n = vec3::norm(axis);
        Ok([axis[0] / n, axis[1] / n, axis[2] / n])
    }

    /// `MSYS/x0,y0,z0,xi,xj,xk,yi,yj,yk` (`scale`: mm per file unit; `moves_before`:
    /// moves were read before it): the MCS the values are in. A second, other MCS is
    /// refused, and a first one other than the identity after moves.
    pub(crate) fn msys(
        &mut self,
        f: &[(&str, At)],
        at: At,
        scale: f64,
        moves_before: Option<At>,
    ) -> Result<(), ClError> {
        let v: [f64; 9] = numbers("MSYS (origin x,y,z, X axis i,j,k, Y axis i,j,k)", f, at)?;
        let mut origin_mm = [0.0; 3];
        for i in 0..3 {
            origin_mm[i] = coordinate(v[i] * scale, f[i].1, "MSYS origin", f[i].0)?;
        }
        let mcs = Mcs {
            origin_mm,
            x: [v[3], v[4], v[5]],
            y: [v[6], v[7], v[8]],
        };
        if !orthonormal(&[mcs.x, mcs.y]) {
            return Err(e(at, "MSYS: the X and Y axes are not orthonormal: refused"));
        }
        let before = match (self.mcs, moves_before) {
            (Some(b), _) => b,
            // Moves before any MSYS: they were in the frame of the file as it stands.
            (None, Some(m)) => (Mcs::IDENTITY, m),
            (None, None) => {
                self.mcs = Some((mcs, at));
                return Ok(());
            }
        };
        if !before.0.same(&mcs) {
            return Err(e(
                at,
                format!(
                    "MSYS names a machine coordinate system (origin {}, X {}, Y {}) other than the one the values before it are in (since line {}): NX writes the GOTOs after it in that MCS, and the program would need another work offset or frame, which polepatch does not write: refused (post each MCS's tool paths as a program of its own)",
                    fmt3(mcs.origin_mm),
                    fmt3(mcs.x),
                    fmt3(mcs.y),
                    before.1.line
                ),
            ));
        }
        self.mcs.get_or_insert(before);
        Ok(())
    }
}

/// The error for a record that transforms, repeats or moves the frame of the values and
/// is not read (module docs), or `None` for any other record.
pub(crate) fn refused_frame_record(word: &str, at: At) -> Option<ClError> {
    let why = match word {
        "TRACUT" => {
            "TRACUT transforms the cutter locations after it by its matrix — or, as some CAM systems pass it on, states the transformation already applied to them — and the file does not say which"
        }
        "INDEX" | "COPY" => {
            "INDEX … COPY repeat the records between them, transformed; polepatch does not expand them"
        }
        "REFSYS" => "REFSYS sets the frame the values after it are given in",
        "TRANS" | "ORIGIN" => "it moves the program zero of the values after it",
        _ => return None,
    };
    Some(
        e(
            at,
            format!(
                "{word} records are not posted: {why}; refused rather than post a moved part (give --ignore {word} only if the values are already in the frame the program is run in)"
            ),
        )
        .refusing(word),
    )
}

#[cfg(test)]
mod tests {
    use crate::{ClItem, parse, parse_with};

    fn pts(text: &str) -> Vec<([f64; 3], [f64; 3])> {
        parse(text.as_bytes())
            .unwrap()
            .points()
            .map(|p| (p.pos_mm, p.axis))
            .collect()
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12)
    }

    /// The repro: a CSYS turned 90° about Z leaves the GOTO where it is (CAMWorks
    /// writes world coordinates after TRNTYP/WORLD); without TRNTYP it is refused.
    #[test]
    fn csys_does_not_move_world_values() {
        let p = pts("TRNTYP/WORLD,0,0,0\nCSYS/0,-1.,0,0,1.,0,0,0,0,0,1.,0\nGOTO/10.,0,5.,0,0,1.\n");
        assert_eq!(p, [([10.0, 0.0, 5.0], [0.0, 0.0, 1.0])]);
        let e = parse(b"CSYS/0,-1.,0,0,1.,0,0,0,0,0,1.,0\nGOTO/10.,0,5.,0,0,1.\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 1), "{e}");
        assert!(
            e.message.contains("CSYS other than the identity")
                && e.message.contains("without TRNTYP/WORLD"),
            "{e}"
        );
        // The identity needs no TRNTYP.
        assert_eq!(pts("CSYS/1,0,0,0,0,1,0,0,0,0,1,0\nGOTO/1,2,3\n").len(), 1);
    }

    /// A setup tilted to the tool along +X (R's third column), moved by (0, 33, 19): the
    /// 6-value GOTOs, the circle and GODLTA keep their world values; the 3-value GOTOs take
    /// the setup's tool axis until a GOTO states another; an identity CSYS puts it back to
    /// +Z.
    #[test]
    fn csys_gives_the_setup_tool_axis_only() {
        let text = "UNIT/MM\nTRNTYP/WORLD,0,0,0\nCSYS/0,0,1.,0,0,1.,0,33.,-1.,0,0,19.\nFEDRAT/100\n\
                    GOTO/80.,10.,-5.\nGOTO/78.,10.,-5.,1.,0,0\nCIRCLE/78.,10.,-10.,-1.,0,0\n\
                    GOTO/78.,15.,-10.\nGODLTA/2.\nGOTO/70.,0,0,.6,0,.8\nGOTO/70.,1.,0\n\
                    TRNTYP/WORLD,0,0,0\nCSYS/1.,0,0,0,0,1.,0,0,0,0,1.,0\nGOTO/0,0,50.\n";
        let cl = parse(text.as_bytes()).unwrap();
        let p: Vec<_> = cl.points().collect();
        assert!(close(p[0].pos_mm, [80.0, 10.0, -5.0]) && close(p[0].axis, [1.0, 0.0, 0.0]));
        assert!(close(p[1].pos_mm, [78.0, 10.0, -5.0]) && close(p[1].axis, [1.0, 0.0, 0.0]));
        let crate::MoveKind::Arc(a) = &p[2].kind else {
            panic!("{:?}", p[2].kind)
        };
        assert!(close(a.center_mm, [78.0, 10.0, -10.0]));
        assert!(close(p[2].pos_mm, [78.0, 15.0, -10.0]));
        assert!(close(p[3].pos_mm, [80.0, 15.0, -10.0]), "GODLTA along +X");
        assert!(close(p[4].axis, [0.6, 0.0, 0.8]));
        assert!(close(p[5].pos_mm, [70.0, 1.0, 0.0]) && close(p[5].axis, [0.6, 0.0, 0.8]));
        assert!(close(p[6].pos_mm, [0.0, 0.0, 50.0]) && close(p[6].axis, [0.0, 0.0, 1.0]));
    }

    #[test]
    fn bad_csys_and_trntyp_are_refused_at_their_record() {
        for (text, at, what) in [
            (
                "TRNTYP/WORLD,0,0,0\nCSYS/1,0,0,0,0,2,0,0,0,0,1,0\nGOTO/0,0,0\n",
                (2, 1),
                "not a rotation",
            ),
            // A mirror (det −1).
            (
                "TRNTYP/WORLD,0,0,0\nCSYS/1,0,0,0,0,1,0,0,0,0,-1,0\nGOTO/0,0,0\n",
                (2, 1),
                "not a rotation",
            ),
            (
                "CSYS/1,0,0,0\nGOTO/0,0,0\n",
                (1, 6),
                "needs 12 values; got 4",
            ),
            (
                "TRNTYP/WORLD,0,0,0\nCSYS/1,0,0,0,0,1,0,x,0,0,1,0\nGOTO/0,0,0\n",
                (2, 20),
                "'x' is not a number",
            ),
            (
                "TRNTYP/LOCAL,0,0,0\nGOTO/0,0,0\n",
                (1, 1),
                "TRNTYP other than WORLD",
            ),
            (
                "TRNTYP/WORLD,5,0,0\nGOTO/0,0,0\n",
                (1, 1),
                "TRNTYP other than WORLD",
            ),
        ] {
            let e = parse(text.as_bytes()).unwrap_err();
            assert_eq!((e.line, e.column), at, "{text}: {e}");
            assert!(e.message.contains(what), "{text}: {e}");
        }
    }

    /// NX: the GOTOs are in the MCS whatever MSYS says; the same MCS again is read, another
    /// one refused at its record, as is a first MSYS other than the identity after moves.
    #[test]
    fn msys_names_the_frame_of_the_values() {
        let mcs = "MSYS/100.,50.,-20.,0,1.,0,-1.,0,0\n";
        let text = format!("{mcs}GOTO/1.,2.,3.,0,0,1.\n{mcs}GOTO/4.,5.,6.\n");
        assert_eq!(
            pts(&text),
            [
                ([1.0, 2.0, 3.0], [0.0, 0.0, 1.0]),
                ([4.0, 5.0, 6.0], [0.0, 0.0, 1.0])
            ]
        );
        let other = format!("{mcs}GOTO/1.,2.,3.\nMSYS/100.,50.,-20.,1.,0,0,0,1.,0\nGOTO/0,0,0\n");
        let e = parse(other.as_bytes()).unwrap_err();
        assert_eq!((e.line, e.column), (3, 1), "{e}");
        assert!(
            e.message.contains("other than the one") && e.message.contains("since line 1"),
            "{e}"
        );
        let late = format!("GOTO/1.,2.,3.\n{mcs}GOTO/0,0,0\n");
        let e = parse(late.as_bytes()).unwrap_err();
        assert_eq!((e.line, e.column), (2, 1), "{e}");
        // The identity after moves is the frame they were in.
        assert_eq!(
            pts("GOTO/1,2,3\nMSYS/0,0,0,1,0,0,0,1,0\nGOTO/0,0,0\n").len(),
            2
        );
        let e = parse(b"MSYS/0,0,0,1,0,0,0.5,1,0\nGOTO/0,0,0\n").unwrap_err();
        assert!(e.message.contains("not orthonormal"), "{e}");
        let e = parse(b"MSYS/0,0,0,1,0,0\nGOTO/0,0,0\n").unwrap_err();
        assert!(e.message.contains("needs 9 values; got 6"), "{e}");
    }

    #[test]
    fn records_that_move_the_frame_are_refused_by_name() {
        for w in [
            "TRACUT/1,0,0,5,0,1,0,0,0,0,1,0",
            "INDEX/1",
            "COPY/1,XYROT,90,3",
            "REFSYS/1,0,0,0,0,1,0,0,0,0,1,0",
            "TRANS/0,0,10",
            "ORIGIN/0,0,10",
        ] {
            let e = parse(format!("GOTO/0,0,0\n  {w}\nGOTO/1,0,0\n").as_bytes()).unwrap_err();
            let name = w.split('/').next().unwrap();
            assert_eq!((e.line, e.column), (2, 3), "{w}: {e}");
            assert!(
                e.message
                    .starts_with(&format!("{name} records are not posted:"))
                    && e.message.contains("moved part"),
                "{w}: {e}"
            );
        }
        // Skipped on request, like any record polepatch refuses.
        let opts = crate::ParseOptions {
            ignore: vec!["TRACUT".into()],
            ..Default::default()
        };
        let p = parse_with(b"TRACUT/NOMORE\nGOTO/0,0,0\n", &opts).unwrap();
        assert_eq!(p.skipped["TRACUT"].count, 1);
        assert!(matches!(p.items[0], ClItem::Move(_)));
    }
}
