//! 8-bit PNG outputs (tone-mapped images, difference pictures): the one
//! place that encodes them, deterministically (same pixels, same bytes).

/// Encodes 8-bit RGB pixels (row-major, top row first) as a PNG file's
/// bytes.
pub fn encode_png(width: usize, height: usize, pixels: &[[u8; 3]]) -> Result<Vec<u8>, String> {
    use image::ImageEncoder;
    let (w, h) = (u32::try_from(width).map_err(|e| e.to_string())?, u32::try_from(height).map_err(|e| e.to_string())?);
    let bytes: Vec<u8> = pixels.iter().flatten().copied().collect();
    let mut out = Vec::new();
    image::codecs::png::PngEncoder::new(&mut out)
        .write_image(&bytes, w, h, image::ExtendedColorType::Rgb8)
        .map_err(|e| format!("cannot encode PNG: {e}"))?;
    Ok(out)
}
