//! What the quality suite reads beyond the patcher's API: `polepatch bench`, the tests'
//! independent checks and the `zone_times` example measure a patch against these. Nothing
//! here is needed to patch a path ([`crate::patch_path`]); the modules they come from stay
//! private, so that their internals can change without a caller noticing.
//!
//! - the bench reference of a zone ([`zone_reference`], [`Reference`]), and whether a zone
//!   can reach feed at all within a deviation cap ([`reachable`]);
//! - the deviation bound of a joint change between the points ([`deviation_bound_zone`],
//!   of a C-only change [`deviation_bound_sampled`], sampled [`BOUND_SAMPLES_PER_SPAN`]
//!   times per span), the exact deviation of a C change ([`orientation_deviation_deg`]),
//!   and the "not worse" tolerance of verification ([`NOT_WORSE_REL`]);
//! - the zones as the driver patches them ([`merge_zones`], [`zone_core`]);
//! - the analysis per span and the axis splines ([`analyze_spans`], [`SpanFigures`],
//!   [`axis_splines`]).

pub use crate::analysis::{SpanFigures, analyze_spans, axis_splines};
pub use crate::direct::{deviation_bound_sampled, deviation_bound_zone, orientation_deviation_deg};
pub use crate::proof::reachable;
pub use crate::reference::{Reference, ReferenceMethod, zone_reference};
pub use crate::tolerances::{BOUND_SAMPLES_PER_SPAN, NOT_WORSE_REL};
pub use crate::zones::{merge_zones, zone_core};
