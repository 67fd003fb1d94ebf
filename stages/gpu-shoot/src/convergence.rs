//! The convergence record (`--convergence-log`: the unshot fraction and
//! the time after each shot) and its plot (`--plot`: the unshot magnitude
//! fraction, on a log scale, against time, as an SVG).

use crate::Solved;
use schemas::header::Header;
use schemas::lightmap::Convergence;

impl Solved {
    /// The convergence record of this solve on `adapter`.
    pub fn convergence(&self, header: Header, adapter: &str) -> Convergence {
        Convergence { header, adapter: adapter.to_string(), initial_unshot_fraction: self.initial_unshot, setup_seconds: self.work.setup_seconds, shots: self.shots.clone() }
    }
}

/// The plot of `convergence`: one decade per grid line, down to the
/// smallest fraction reached (at least one decade, at most 1e-6).
pub fn plot(convergence: &Convergence) -> String {
    let (w, h, m) = (640.0, 400.0, 50.0);
    let t_max = convergence.shots.last().map(|s| s.seconds).unwrap_or(1.0).max(1e-9);
    let floor = convergence.shots.iter().map(|s| s.unshot_magnitude_fraction).fold(1.0f64, f64::min).max(1e-6);
    let decades = (-floor.log10()).ceil().max(1.0);
    let x = |t: f64| m + (w - 2.0 * m) * t / t_max;
    let y = |f: f64| m + (h - 2.0 * m) * (-f.max(1e-12).log10() / decades).min(1.0);
    let mut points = format!("{:.1},{:.1}", x(0.0), y(convergence.initial_unshot_fraction));
    for s in &convergence.shots {
        points += &format!(" {:.1},{:.1}", x(s.seconds), y(s.unshot_magnitude_fraction));
    }
    let mut svg = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"12\">\n");
    svg += &format!("<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n");
    svg += &format!("<polyline fill=\"none\" stroke=\"black\" points=\"{m},{m} {m},{} {},{}\"/>\n", h - m, w - m, h - m);
    for d in 0..=decades as i32 {
        let yy = y(10f64.powi(-d));
        svg += &format!("<text x=\"4\" y=\"{:.1}\">1e-{d}</text><line x1=\"{m}\" x2=\"{}\" y1=\"{yy:.1}\" y2=\"{yy:.1}\" stroke=\"#ddd\"/>\n", yy + 4.0, w - m);
    }
    svg += &format!("<text x=\"{}\" y=\"{}\">{t_max:.3} s</text>\n", w - m - 30.0, h - m + 16.0);
    svg += &format!("<text x=\"{m}\" y=\"20\">unshot fraction (sum |dB| A / emitted) vs time, {} shots ({})</text>\n", convergence.shots.len(), convergence.adapter);
    svg += &format!("<polyline fill=\"none\" stroke=\"#c33\" stroke-width=\"1.5\" points=\"{points}\"/>\n</svg>\n");
    svg
}
