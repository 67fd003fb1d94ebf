//! The sweep's plot: error (y) against total time (x), both logarithmic,
//! one curve per (solver, gather mode) through its points in grid order
//! (for one knob: its values as given, loosest to tightest in the
//! defaults; ordering by time instead zigzagged where the gather's time
//! dominates and only noise separates the points), each point labelled
//! with its knob values, whiskers over its range across runs, the Pareto
//! front ringed, the reference named in the title. Drawn by `plotters` as SVG
//! and as PNG (its bitmap backend, encoded by [`stage_kit::png`]).
//!
//! The PNG's text is drawn with DejaVu Sans embedded in the binary
//! (`bench/assets/DejaVuSans.ttf`, licence beside it), so it renders on a
//! machine with no font installed; the SVG names `sans-serif` and leaves
//! the font to the viewer.

use super::table::Sweep;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::sync::Once;

/// The plot's size, pixels.
pub const SIZE: (u32, u32) = (960, 640);

/// Curve colours: Tableau's first six, strong enough on white (plotters'
/// Palette99 starts with a pale yellow at its third).
const COLOURS: [RGBColor; 6] =
    [RGBColor(31, 119, 180), RGBColor(214, 39, 40), RGBColor(44, 160, 44), RGBColor(148, 103, 189), RGBColor(255, 127, 14), RGBColor(23, 190, 207)];

/// The embedded font.
static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, FONT)
            .unwrap_or_else(|_| panic!("the embedded DejaVu Sans is a valid font"));
    });
}

/// The plot as SVG text.
pub fn svg(sweep: &Sweep) -> Result<String, String> {
    register_font();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw(&root, sweep)?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(text)
}

/// The plot as PNG bytes.
pub fn png(sweep: &Sweep) -> Result<Vec<u8>, String> {
    register_font();
    let (w, h) = SIZE;
    let mut buffer = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, SIZE).into_drawing_area();
        draw(&root, sweep)?;
        root.present().map_err(|e| e.to_string())?;
    }
    let pixels: Vec<[u8; 3]> = buffer.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    stage_kit::png::encode_png(w as usize, h as usize, &pixels)
}

/// A logarithmic axis range holding every positive finite value, out to
/// whole decades (plotters labels a log axis from its first power of ten
/// up, so a range starting at 0.016 left 0.02 .. 0.09 unlabelled); 1 to
/// 10 when there is no value.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.filter(|v| v.is_finite() && *v > 0.0).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return 1.0..10.0;
    }
    // A little room first, so a point never sits on the frame.
    let (lo, hi) = (lo / 1.1, hi * 1.1);
    let (lo, hi) = (10f64.powf(lo.log10().floor()), 10f64.powf(hi.log10().ceil()));
    let hi = if hi > lo { hi } else { hi * 10.0 };
    // Just outside the decades, so rounding in plotters' own logarithms
    // cannot drop the end ticks.
    lo * (1.0 - 1e-9)..hi * (1.0 + 1e-9)
}

fn draw<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, sweep: &Sweep) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let plotted = |x: f64, y: f64| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0;
    let points: Vec<_> = sweep.points.iter().filter(|p| plotted(p.total_s.median, p.error.median)).collect();
    let x_range = log_range(points.iter().flat_map(|p| [p.total_s.min, p.total_s.max]));
    let y_range = log_range(points.iter().flat_map(|p| [p.error.min, p.error.max]));
    let mut chart = ChartBuilder::on(root)
        .caption(format!("{}: error against time; {}", sweep.scene, sweep.reference.label), ("sans-serif", 20))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x_range.log_scale(), y_range.log_scale())
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(format!(
            "total time of the point's stages, s ({}; mesh-prep not included)",
            if sweep.reps == 1 { "one run".to_string() } else { format!("median of {} runs", sweep.reps) }
        ))
        .y_desc(format!("error: {}", short_metric(&sweep.error_metric)))
        // Enough key points for plotters to place one at every 1..9 x 10^k
        // (its log axis otherwise labels the powers of ten only), labelled
        // at 1, 2 and 5 x 10^k.
        .x_labels(40)
        .y_labels(40)
        .max_light_lines(0)
        .x_label_formatter(&|v| tick_125(*v))
        .y_label_formatter(&|v| tick_125(*v))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 15))
        .draw()
        .map_err(e)?;

    let mut curves: Vec<(String, Vec<_>)> = Vec::new();
    for p in &points {
        let name = format!("{}, {}", p.solver, p.gather);
        match curves.iter_mut().find(|(n, _)| *n == name) {
            Some((_, members)) => members.push(*p),
            None => curves.push((name, vec![*p])),
        }
    }
    for (i, (name, members)) in curves.iter().enumerate() {
        let colour = COLOURS[i % COLOURS.len()].to_rgba();
        let line: Vec<(f64, f64)> = members.iter().map(|p| (p.total_s.median, p.error.median)).collect();
        chart
            .draw_series(LineSeries::new(line.clone(), colour.stroke_width(2)))
            .map_err(e)?
            .label(name.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], colour.stroke_width(2)));
        let whiskers = members.iter().flat_map(|p| {
            let (x, y) = (p.total_s.median, p.error.median);
            [
                PathElement::new(vec![(p.total_s.min, y), (p.total_s.max, y)], colour.stroke_width(1)),
                PathElement::new(vec![(x, p.error.min.max(f64::MIN_POSITIVE)), (x, p.error.max)], colour.stroke_width(1)),
            ]
        });
        chart.draw_series(whiskers).map_err(e)?;
        chart.draw_series(line.iter().map(|&(x, y)| Circle::new((x, y), 4, colour.filled()))).map_err(e)?;
        // Each point's knob values beside it.
        let labels = members.iter().map(|p| {
            let text: Vec<String> = p.knobs.iter().map(|k| format!("{}={}", k.name, knob_text(k.value))).collect();
            EmptyElement::at((p.total_s.median, p.error.median)) + Text::new(text.join(" "), (7, -16), ("sans-serif", 11).into_font().color(&colour))
        });
        chart.draw_series(labels).map_err(e)?;
    }
    let front: Vec<(f64, f64)> = points.iter().filter(|p| p.pareto).map(|p| (p.total_s.median, p.error.median)).collect();
    if !front.is_empty() {
        chart
            .draw_series(front.iter().map(|&(x, y)| Circle::new((x, y), 9, BLACK.stroke_width(2))))
            .map_err(e)?
            .label("Pareto front (no point both faster and more accurate)")
            .legend(|(x, y)| Circle::new((x + 12, y), 6, BLACK.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(e)?;
    Ok(())
}

/// The metric's name up to its first explanation.
fn short_metric(metric: &str) -> &str {
    metric.split(" (").next().unwrap_or(metric)
}

/// A knob value: as given where it is 0.01 or more (`0.01`, `0.999`,
/// `32768`), else in exponent form (`3e-4`).
fn knob_text(v: f64) -> String {
    if v == 0.0 || v.abs() >= 1e-2 {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A tick label at 1, 2 and 5 x 10^k, none elsewhere.
fn tick_125(v: f64) -> String {
    let mantissa = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|m| (mantissa - m).abs() < 1e-6) {
        tick(v)
    } else {
        String::new()
    }
}

/// A tick label: `0.01`, `3e-4`, `20`.
fn tick(v: f64) -> String {
    if (1e-2..1e4).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_ranges_hold_every_value_with_room() {
        let r = log_range([1.5e-3, 2e-2, 0.0, f64::NAN].into_iter());
        assert!((r.start - 1e-3).abs() < 1e-11 && (r.end - 0.1).abs() < 1e-9, "{r:?}");
        assert_eq!(log_range(std::iter::empty()), 1.0..10.0);
        let one = log_range([5.0].into_iter());
        assert!((one.start - 1.0).abs() < 1e-8 && (one.end - 10.0).abs() < 1e-7, "{one:?}");
        // A value on a power of ten gets room beyond it.
        let edge = log_range([1.0, 3.0].into_iter());
        assert!(edge.start < 1.0, "{edge:?}");
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick(0.01), "0.01");
        assert_eq!(tick(20.0), "20");
        assert_eq!(tick(3e-4), "3e-4");
        assert_eq!((tick_125(0.2), tick_125(0.3), tick_125(5e-4), tick_125(100.0)), ("0.2".into(), String::new(), "5e-4".into(), "100".into()));
        assert_eq!((knob_text(3e-4), knob_text(0.999), knob_text(32768.0)), ("3e-4".into(), "0.999".into(), "32768".into()));
    }
}
