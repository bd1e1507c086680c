//! Angles in degrees: wrapping to (−180, 180] and unwrapping near a reference.

/// An angle in degrees wrapped to (−180, 180].
pub fn wrap_deg(angle_deg: f64) -> f64 {
    if angle_deg > -180.0 && angle_deg <= 180.0 {
        return angle_deg;
    }
    let w = angle_deg % 360.0; // exact, in (−360, 360)
    if w > 180.0 {
        w - 360.0
    } else if w <= -180.0 {
        w + 360.0
    } else {
        w
    }
}

/// `angle_deg + n·360` for the integer n that puts it within (ref − 180, ref + 180], degrees.
pub fn unwrap_near_deg(angle_deg: f64, ref_deg: f64) -> f64 {
    ref_deg + wrap_deg(angle_deg - ref_deg)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_and_unwrap() {
        assert_eq!(wrap_deg(180.0), 180.0);
        assert_eq!(wrap_deg(-180.0), 180.0);
        assert_eq!(wrap_deg(540.0), 180.0);
        assert_eq!(wrap_deg(-190.0), 170.0);
        assert_eq!(wrap_deg(0.0), 0.0);
        assert_eq!(unwrap_near_deg(-170.0, 170.0), 190.0);
        assert_eq!(unwrap_near_deg(10.0, 725.0), 730.0);
        assert_eq!(unwrap_near_deg(-1e-20, 0.0), -1e-20);
    }
}
