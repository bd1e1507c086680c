//! Per-zone SVG plots of the suite (the pictures of G16 Figs. 8 and 10): C(s) and the
//! primary axis P(s) before and after, and the Equation-6 feed ratio along s before and
//! after with the limiting axis marked by colour.

use plotters::prelude::*;
use polepatch_kinematics::Axis;

/// One Equation-6 sample of a plot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioSample {
    /// Path parameter, mm.
    pub s_mm: f64,
    /// Overall ratio (bound / F, ≤ 1).
    pub ratio: f64,
    /// C-limited ratio.
    pub c_ratio: f64,
    /// Limiting axis (`None`: the programmed feed binds).
    pub axis: Option<Axis>,
}

/// What a zone's plot shows.
#[derive(Debug, Clone, PartialEq)]
pub struct ZonePlot {
    /// Caption.
    pub title: String,
    /// Letter of the primary axis in the program.
    pub primary_letter: char,
    /// s range of the zone (its patch), mm.
    pub zone_s_mm: (f64, f64),
    /// CL points (s mm, C °) before.
    pub c_points_before: Vec<(f64, f64)>,
    /// CL points (s mm, C °) after, as written.
    pub c_points_after: Vec<(f64, f64)>,
    /// The analysis spline of C before, sampled.
    pub c_curve_before: Vec<(f64, f64)>,
    /// The analysis spline of C after, sampled.
    pub c_curve_after: Vec<(f64, f64)>,
    /// CL points (s mm, P °) before.
    pub p_points_before: Vec<(f64, f64)>,
    /// CL points (s mm, P °) after, as written.
    pub p_points_after: Vec<(f64, f64)>,
    /// The analysis spline of P before, sampled.
    pub p_curve_before: Vec<(f64, f64)>,
    /// The analysis spline of P after, sampled.
    pub p_curve_after: Vec<(f64, f64)>,
    /// Equation-6 samples before.
    pub ratio_before: Vec<RatioSample>,
    /// Equation-6 samples after.
    pub ratio_after: Vec<RatioSample>,
}

/// Colour of a limiting axis (`None`: the feed).
pub fn axis_colour(axis: Option<Axis>) -> RGBColor {
    match axis {
        Some(Axis::X) => RGBColor(214, 39, 40),
        Some(Axis::Y) => RGBColor(44, 160, 44),
        Some(Axis::Z) => RGBColor(31, 119, 180),
        Some(Axis::Primary) => RGBColor(255, 127, 14),
        Some(Axis::C) => RGBColor(148, 103, 189),
        None => RGBColor(127, 127, 127),
    }
}

/// Width and height of a plot, pixels.
pub const SIZE_PX: (u32, u32) = (900, 1000);

/// Render `p` as an SVG document.
pub fn render_svg(p: &ZonePlot) -> Result<String, String> {
    let mut buf = String::new();
    draw(p, &mut buf).map_err(|e| format!("plot {}: {e}", p.title))?;
    Ok(buf)
}

fn range(vals: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-3);
    (lo - pad, hi + pad)
}

fn draw(p: &ZonePlot, buf: &mut String) -> Result<(), Box<dyn std::error::Error>> {
    let root = SVGBackend::with_string(buf, SIZE_PX).into_drawing_area();
    root.fill(&WHITE)?;
    let root = root.titled(&p.title, ("sans-serif", 18))?;
    let areas = root.split_evenly((3, 1));
    let (top, middle, bottom) = (&areas[0], &areas[1], &areas[2]);
    let (x0, x1) = range(p.c_curve_before.iter().map(|q| q.0));
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    let zone_fill = RGBColor(240, 240, 200);

    // Top: C(s); middle: P(s).
    let axis_panels = [
        (
            top,
            "C, °".to_string(),
            "C",
            (&p.c_curve_before, &p.c_points_before),
            (&p.c_curve_after, &p.c_points_after),
        ),
        (
            middle,
            format!("{}, °", p.primary_letter),
            "primary",
            (&p.p_curve_before, &p.p_points_before),
            (&p.p_curve_after, &p.p_points_after),
        ),
    ];
    for (area, desc, what, (cb, pb), (ca, pa)) in axis_panels {
        let (y0, y1) = range(cb.iter().chain(ca.iter()).map(|q| q.1));
        let mut chart = ChartBuilder::on(area)
            .margin(10)
            .x_label_area_size(35)
            .y_label_area_size(60)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart.configure_mesh().x_desc("s, mm").y_desc(desc).draw()?;
        chart.draw_series(std::iter::once(Rectangle::new(
            [(p.zone_s_mm.0, y0), (p.zone_s_mm.1, y1)],
            zone_fill.filled(),
        )))?;
        chart
            .draw_series(LineSeries::new(cb.iter().copied(), blue.stroke_width(1)))?
            .label(format!("{what} before (analysis spline, CL points)"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], blue));
        chart.draw_series(pb.iter().map(|&q| Circle::new(q, 2, blue.filled())))?;
        chart
            .draw_series(LineSeries::new(ca.iter().copied(), red.stroke_width(2)))?
            .label(format!("{what} after, as written"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red));
        chart.draw_series(pa.iter().map(|&q| Circle::new(q, 2, red.filled())))?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperLeft)
            .draw()?;
    }

    // Bottom: the Equation-6 ratio, coloured by the limiting axis.
    let mut chart = ChartBuilder::on(bottom)
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(x0..x1, 0.0..1.08)?;
    chart
        .configure_mesh()
        .x_desc("s, mm")
        .y_desc("Eq. 6 feed bound / F")
        .draw()?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(p.zone_s_mm.0, 0.0), (p.zone_s_mm.1, 1.08)],
        zone_fill.filled(),
    )))?;
    for (samples, after) in [(&p.ratio_before, false), (&p.ratio_after, true)] {
        // Consecutive samples with the same limiting axis form one line.
        let mut k = 0;
        while k < samples.len() {
            let axis = samples[k].axis;
            let mut e = k;
            while e + 1 < samples.len() && samples[e + 1].axis == axis {
                e += 1;
            }
            let end = (e + 1).min(samples.len() - 1);
            let pts: Vec<(f64, f64)> = samples[k..=end].iter().map(|q| (q.s_mm, q.ratio)).collect();
            let col = axis_colour(axis);
            let style = if after {
                col.stroke_width(3)
            } else {
                col.mix(0.45).stroke_width(1)
            };
            chart.draw_series(LineSeries::new(pts, style))?;
            k = e + 1;
        }
    }
    // Legend: one entry per axis colour, and the line widths.
    let letter = |a: Axis| match a {
        Axis::X => 'X',
        Axis::Y => 'Y',
        Axis::Z => 'Z',
        Axis::Primary => p.primary_letter,
        Axis::C => 'C',
    };
    for axis in Axis::ALL.iter().map(|&a| Some(a)).chain([None]) {
        let col = axis_colour(axis);
        let name = match axis {
            Some(a) => format!("{} limits", letter(a)),
            None => "F (feed reached)".to_string(),
        };
        chart
            .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(3)));
    }
    let grey = RGBColor(90, 90, 90);
    chart
        .draw_series(std::iter::empty::<PathElement<(f64, f64)>>())?
        .label("thin, light: before; thick: after")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey.mix(0.45)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()?;
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn renders_an_svg_with_paths() {
        let line: Vec<(f64, f64)> = (0..20).map(|k| (k as f64, (k * k) as f64)).collect();
        let samples: Vec<RatioSample> = (0..20)
            .map(|k| RatioSample {
                s_mm: k as f64,
                ratio: if k < 10 { 0.5 } else { 1.0 },
                c_ratio: 0.5,
                axis: if k < 10 { Some(Axis::C) } else { None },
            })
            .collect();
        let p = ZonePlot {
            title: "planted".into(),
            primary_letter: 'A',
            zone_s_mm: (5.0, 12.0),
            c_points_before: line.clone(),
            c_points_after: line.clone(),
            c_curve_before: line.clone(),
            c_curve_after: line.clone(),
            p_points_before: line.clone(),
            p_points_after: line.clone(),
            p_curve_before: line.clone(),
            p_curve_after: line,
            ratio_before: samples.clone(),
            ratio_after: samples,
        };
        let svg = render_svg(&p).unwrap();
        assert!(svg.trim_start().starts_with("<svg"), "{}", &svg[..80]);
        assert!(svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("<polyline") || svg.contains("<path"));
        assert!(svg.contains("C limits"));
        assert!(svg.contains("primary after"), "the primary axis' panel");
    }
}
