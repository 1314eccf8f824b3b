//! Writing 8-bit sRGB PNG files (with the `png` crate).

/// Writes 8-bit RGB pixels (row-major, 3 bytes each) as a compressed PNG file.
pub fn write_rgb8(path: &std::path::Path, width: u32, height: u32, rgb: &[u8]) -> std::io::Result<()> {
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::High);
    let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
    writer.write_image_data(rgb).map_err(std::io::Error::other)
}

/// Writes linear RGB radiance as an sRGB PNG (clamped to [0, 1]).
pub fn write_srgb(
    path: &std::path::Path,
    width: u32,
    height: u32,
    linear: &[[f32; 3]],
) -> std::io::Result<()> {
    let encode_channel = |c: f32| {
        let c = c.clamp(0.0, 1.0);
        let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0 + 0.5) as u8
    };
    let bytes: Vec<u8> = linear.iter().flat_map(|p| p.map(encode_channel)).collect();
    write_rgb8(path, width, height, &bytes)
}
