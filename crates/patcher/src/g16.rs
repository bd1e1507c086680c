//! The G16 patch (SPEC §3 steps 3–5): split, fit C_b and C_a, join search, patch QP.
