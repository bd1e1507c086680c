//! Test helpers shared by the unit tests of this crate.

use crate::machine::{Machine, PrimaryAxis};

/// The UCP710 limits with another primary kind, senses and primary range.
pub(crate) fn machine(primary: PrimaryAxis, sp: f64, sc: f64, range_deg: (f64, f64)) -> Machine {
    let mut m = Machine::builtin("mikron-ucp710").unwrap();
    m.rotary = crate::rotary::Rotaries::table_table(match primary {
        PrimaryAxis::A => 'A',
        PrimaryAxis::B => 'B',
    });
    m.primary_sense = sp;
    m.c_sense = sc;
    m.primary_range_deg = range_deg;
    m
}

/// Every combination of primary kind and senses, primary range (−120, 120).
pub(crate) fn all_kinds() -> Vec<Machine> {
    let mut out = Vec::new();
    for primary in [PrimaryAxis::A, PrimaryAxis::B] {
        for sp in [1.0, -1.0] {
            for sc in [1.0, -1.0] {
                out.push(machine(primary, sp, sc, (-120.0, 120.0)));
            }
        }
    }
    out
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny deterministic generator for seeded sweeps.
pub(crate) struct SplitMix64(pub u64);

impl SplitMix64 {
    /// Next 64 random bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [lo, hi).
    pub(crate) fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
    /// One of `items`, uniformly.
    pub(crate) fn pick<T: Copy>(&mut self, items: &[T]) -> T {
        items[(self.next_u64() % items.len() as u64) as usize]
    }
}

/// The UCP710 limits with any pair: pole axis `a` (letter C), tilting axis `b` (letter B),
/// tool `t0` (unit vectors), senses, both table axes, primary range (−180, 180].
pub(crate) fn pair_machine(a: [f64; 3], b: [f64; 3], t0: [f64; 3], sp: f64, sc: f64) -> Machine {
    use crate::rotary::{Carrier, Rotaries, RotaryAxis};
    let mut m = Machine::builtin("mikron-ucp710").unwrap();
    m.rotary = Rotaries {
        primary: RotaryAxis {
            letter: 'B',
            carrier: Carrier::Table,
            direction: b,
        },
        c: RotaryAxis {
            letter: 'C',
            carrier: Carrier::Table,
            direction: a,
        },
        tool_direction: t0,
    };
    m.primary_sense = sp;
    m.c_sense = sc;
    m.primary_range_deg = (-180.0, 180.0);
    m
}

/// A unit vector from three numbers (not all near zero).
pub(crate) fn unit(v: [f64; 3]) -> [f64; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}
