//! The strategy table: which methods answer a zone, in which order, and whether their
//! proposals are verified. The top of the crate: it names every method and hands them to
//! the driver as [`Proposer`]s ([`crate::driver::patch_with`]), which never names one
//! (ripgrep's `Searcher` never names its `Sink`s).
//!
//! | [`Strategy`] | [`PatchAxes`] | methods, in order | verified |
//! |---|---|---|---|
//! | `Polepatch` | `Both` | [`Reselect`], [`JointMethod`] | yes |
//! | `Polepatch` | `OnlyC` | [`COnly`] (G16's patch, the direct QP) | yes |
//! | `Freeze`, `Linearize`, `Smooth` | either | [`Peer`] (the rule, as it is) | no |

use crate::{
    c_only::COnly,
    driver::{PatchResult, patch_with},
    joint_method::JointMethod,
    path::{Path, PathError},
    peers::Peer,
    protocol::Proposer,
    reselect::Reselect,
};
use polepatch_kinematics::Machine;

pub use crate::options::{PatchAxes, PatchOptions, Strategy};

/// The methods of a strategy, in the order they are asked, and whether their proposals
/// are verified (a peer's rule is scored as it is, never held back).
pub fn methods(opts: &PatchOptions) -> (Vec<Box<dyn Proposer>>, bool) {
    match (opts.strategy, opts.axes) {
        (Strategy::Polepatch, PatchAxes::Both) => {
            (vec![Box::new(Reselect), Box::new(JointMethod)], true)
        }
        (Strategy::Polepatch, PatchAxes::OnlyC) => (vec![Box::new(COnly::default())], true),
        (peer, _) => (vec![Box::new(Peer(peer))], false),
    }
}

/// Patch every singular zone of `path` with the methods of `opts`' strategy (module
/// docs).
pub fn patch_path(
    path: &Path,
    machine: &Machine,
    opts: &PatchOptions,
) -> Result<PatchResult, PathError> {
    let (m, verify) = methods(opts);
    patch_with(path, machine, opts, m, verify)
}
