//! An 8-bit sRGB canvas with anti-aliased text: the labels of the sweep images, drawn with
//! `ab_glyph` from DejaVu Sans, which the `dejavu` crate embeds (no system font needed; the
//! DejaVu licence is permissive, derived from Bitstream Vera's).

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};

/// An sRGB colour, 8 bits per channel.
pub type Rgb8 = [u8; 3];

pub const WHITE: Rgb8 = [255, 255, 255];
pub const BLACK: Rgb8 = [0, 0, 0];

/// Horizontal placement of a text relative to its x coordinate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    Left,
    Center,
}

/// The font of every label: DejaVu Sans (regular and bold).
pub struct Fonts {
    regular: FontRef<'static>,
    bold: FontRef<'static>,
}

/// A font weight.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Weight {
    Regular,
    Bold,
}

impl Fonts {
    pub fn new() -> Self {
        let load =
            |bytes: &'static [u8]| FontRef::try_from_slice(bytes).expect("the embedded DejaVu font parses");
        Self { regular: load(dejavu::sans::regular()), bold: load(dejavu::sans::bold()) }
    }

    fn font(&self, weight: Weight) -> &FontRef<'static> {
        match weight {
            Weight::Regular => &self.regular,
            Weight::Bold => &self.bold,
        }
    }

    /// The advance width of `text` at `px` pixels.
    pub fn width(&self, text: &str, px: f32, weight: Weight) -> f32 {
        let font = self.font(weight).as_scaled(PxScale::from(px));
        let mut width = 0.0;
        let mut previous = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = previous {
                width += font.kern(p, id);
            }
            width += font.h_advance(id);
            previous = Some(id);
        }
        width
    }
}

/// Row-major 8-bit sRGB pixels.
pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Rgb8>,
}

impl Canvas {
    pub fn new(width: u32, height: u32, background: Rgb8) -> Self {
        Self { width, height, pixels: vec![background; (width * height) as usize] }
    }

    /// Fills the rectangle [x, x + w) × [y, y + h), clipped to the canvas.
    pub fn fill(&mut self, x: u32, y: u32, w: u32, h: u32, colour: Rgb8) {
        for yy in y..(y + h).min(self.height) {
            for xx in x..(x + w).min(self.width) {
                self.pixels[(yy * self.width + xx) as usize] = colour;
            }
        }
    }

    /// Copies a `w`-pixel-wide image with its top left corner at (x, y), clipped.
    pub fn blit(&mut self, x: u32, y: u32, w: u32, image: &[Rgb8]) {
        for (row, line) in image.chunks_exact(w as usize).enumerate() {
            let yy = y + row as u32;
            if yy >= self.height {
                break;
            }
            for (col, &p) in line.iter().enumerate() {
                let xx = x + col as u32;
                if xx < self.width {
                    self.pixels[(yy * self.width + xx) as usize] = p;
                }
            }
        }
    }

    /// Draws `text` at `px` pixels with its top (the font's ascent) at y; blends coverage in
    /// sRGB (good enough for labels).
    #[allow(clippy::too_many_arguments)]
    pub fn text(
        &mut self,
        fonts: &Fonts,
        text: &str,
        x: f32,
        y: f32,
        px: f32,
        weight: Weight,
        align: Align,
        colour: Rgb8,
    ) {
        let font = fonts.font(weight).as_scaled(PxScale::from(px));
        let x0 = match align {
            Align::Left => x,
            Align::Center => x - 0.5 * fonts.width(text, px, weight),
        };
        let baseline = y + font.ascent();
        let mut caret = x0;
        let mut previous = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = previous {
                caret += font.kern(p, id);
            }
            let glyph = id.with_scale_and_position(PxScale::from(px), point(caret, baseline));
            caret += font.h_advance(id);
            previous = Some(id);
            let Some(outline) = fonts.font(weight).outline_glyph(glyph) else { continue };
            let bounds = outline.px_bounds();
            outline.draw(|gx, gy, coverage| {
                let (px_x, px_y) = (bounds.min.x as i64 + i64::from(gx), bounds.min.y as i64 + i64::from(gy));
                if px_x < 0 || px_y < 0 || px_x >= i64::from(self.width) || px_y >= i64::from(self.height) {
                    return;
                }
                let p = &mut self.pixels[(px_y as u32 * self.width + px_x as u32) as usize];
                let a = coverage.clamp(0.0, 1.0);
                for (d, s) in p.iter_mut().zip(colour) {
                    *d = (f32::from(*d) * (1.0 - a) + f32::from(s) * a + 0.5) as u8;
                }
            });
        }
    }

    /// The pixels as bytes, for the PNG encoder.
    pub fn bytes(&self) -> Vec<u8> {
        self.pixels.iter().flatten().copied().collect()
    }
}

/// Encodes linear radiance to 8-bit sRGB (clamped to [0, 1]).
pub fn srgb8(linear: [f32; 3]) -> Rgb8 {
    linear.map(|c| {
        let c = if c.is_finite() { c.clamp(0.0, 1.0) } else { 0.0 };
        let s = if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (s * 255.0 + 0.5) as u8
    })
}
