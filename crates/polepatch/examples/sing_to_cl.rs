//! Write C17's `%SING` as a CL file (APT), the bundled example of `polepatch post`:
//! `cargo run -p polepatch --example sing_to_cl > fixtures/cl/SING.apt`.
//! The cutter locations are the tool tip and tool axis of every move under TCPM, from the
//! UCP710's forward kinematics.

use polepatch::cl::{ClPoint, to_apt};
use polepatch::kinematics::{Machine, forward};
use polepatch::load_nc;
use polepatch::nc::{Motion, modal};

fn main() {
    let machine = Machine::builtin("mikron-ucp710").expect("built-in");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let bytes = std::fs::read(root.join("fixtures/c17/SING.I")).expect("SING.I");
    let lp = load_nc(&bytes, "SING.I", &machine, None).expect("loads");
    let p = &lp.program;
    let points: Vec<ClPoint> = (0..p.blocks.len())
        .filter(|&b| p.blocks[b].is_move && p.state(b).tcpm.is_on())
        .filter_map(|b| {
            let st = p.state(b);
            let v = |i: usize| st.pos[i];
            Some(ClPoint::straight(
                [v(modal::X)?, v(modal::Y)?, v(modal::Z)?],
                forward(&machine, v(modal::A)?, v(modal::C)?),
                st.feed_mm_min,
                st.motion == Motion::Rapid,
                p.blocks[b].line,
            ))
        })
        .collect();
    print!("{}", to_apt(&points, "SING", 7));
}
