//! Colour quantities.

/// Luminance weight of linear Rec. 709 / sRGB primaries (ITU-R BT.709):
/// `Y = 0.2126 R + 0.7152 G + 0.0722 B`.
pub fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

/// The largest of the three channels.
pub fn max_channel(rgb: [f64; 3]) -> f64 {
    rgb[0].max(rgb[1]).max(rgb[2])
}
