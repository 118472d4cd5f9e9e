//! Colours: the sRGB transfer between the linear values the shading
//! works in and the 8-bit values images hold (IEC 61966-2-1), and the
//! ragdolls' palette, shared by figure 1 and the side views so a ragdoll
//! has the same colour in both.

use glam::Vec3;

/// One 8-bit sRGB channel to linear (0 to 1).
pub fn to_linear(channel: u8) -> f32 {
    let c = f32::from(channel) / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear value (clamped to 0 to 1) to an 8-bit sRGB channel.
pub fn to_srgb(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let encoded = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (encoded * 255.0).round() as u8
}

/// An 8-bit sRGB colour as linear RGB.
pub fn linear_rgb(rgb: [u8; 3]) -> Vec3 {
    Vec3::new(to_linear(rgb[0]), to_linear(rgb[1]), to_linear(rgb[2]))
}

/// Ragdoll `index`'s colour (8-bit sRGB): hues a golden angle (137.5
/// degrees) apart, so neighbours in the list differ most, at three
/// brightnesses in turn, so the hues that come round again after 8 or so
/// still differ.
pub fn ragdoll_colour(index: usize) -> [u8; 3] {
    let hue = (index as f32 * 137.507_77).rem_euclid(360.0);
    let value = [0.95, 0.8, 0.65][index % 3];
    hsv(hue, 0.68, value)
}

/// `rgb` as `#rrggbb`.
pub fn hex(rgb: [u8; 3]) -> String {
    format!("#{:02x}{:02x}{:02x}", rgb[0], rgb[1], rgb[2])
}

/// Hue (degrees), saturation and value (0 to 1) to 8-bit RGB.
fn hsv(hue: f32, saturation: f32, value: f32) -> [u8; 3] {
    let chroma = value * saturation;
    let sector = hue / 60.0;
    let x = chroma * (1.0 - (sector.rem_euclid(2.0) - 1.0).abs());
    let (r, g, b) = match sector as u32 {
        0 => (chroma, x, 0.0),
        1 => (x, chroma, 0.0),
        2 => (0.0, chroma, x),
        3 => (0.0, x, chroma),
        4 => (x, 0.0, chroma),
        _ => (chroma, 0.0, x),
    };
    let m = value - chroma;
    [r, g, b].map(|c| ((c + m) * 255.0).round() as u8)
}
