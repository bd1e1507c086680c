//! The dialects of NC code polepatch reads and writes.

/// Dialect of the file (detected, or forced by the caller).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dialect {
    /// Detect from the text ([`crate::program::detect`]).
    #[default]
    Auto,
    /// Heidenhain in ISO mode (`%NAME G71 *`, `N10 G01 X+1 *`).
    Heidenhain,
    /// Heidenhain conversational (Klartext: `BEGIN PGM`, `L X+10 C+90 R0 F2000`); see
    /// [`crate::conversational`].
    Conversational,
    /// Siemens Sinumerik.
    Sinumerik,
    /// Fanuc and the ISO controllers like it (Haas, LinuxCNC, grblHAL, Mazak ISO, …).
    Fanuc,
    /// Heidenhain (Philips) MillPlus: ISO words with its own G codes (`G7` tilted plane,
    /// `G93` datum shift, `G141` TCPM, `G81`… cycle definitions) and indexed addresses
    /// (`A5=15.`); see [`crate::millplus`].
    MillPlus,
}
