//! The images of a render: channels composed with the highlight, memory read out as an image,
//! and the difference image.

use super::visibility::BACKGROUND;
use golden::specular::C_FRAC;

/// The highlight of a specular output pixel (UQ8.8) in 8-bit levels, rounded.
pub fn spec_level(spec: u16) -> u32 {
    (spec as u32 + (1 << (C_FRAC - 1))) >> C_FRAC
}

/// A channel of the image out of memory: background (never written) 0.
pub(super) fn memory_image(frame: &golden::raster::Frame) -> Vec<u8> {
    let w = frame.width();
    (0..w * frame.height()).map(|k| frame.get(k % w, k / w).unwrap_or(0)).collect()
}

/// Diffuse channels plus the white highlight, saturated; background 0.
pub(super) fn compose(diffuse: &[Vec<u8>], spec: Option<&[u16]>, owner: &[u32]) -> Vec<u8> {
    let channels = diffuse.len();
    let mut img = vec![0u8; owner.len() * channels];
    for (idx, &o) in owner.iter().enumerate() {
        if o == BACKGROUND {
            continue;
        }
        let hi = spec.map_or(0, |s| spec_level(s[idx]));
        for c in 0..channels {
            img[idx * channels + c] = (diffuse[c][idx] as u32 + hi).min(255) as u8;
        }
    }
    img
}

/// A difference image (RGB): matching pixels as a dim gray copy of golden, differing pixels
/// bright red (brighter the larger the difference).
pub fn difference_image(rtl: &[u8], golden: &[u8], channels: usize) -> Vec<u8> {
    let mut out = Vec::with_capacity(rtl.len() / channels * 3);
    for (a, b) in rtl.chunks(channels).zip(golden.chunks(channels)) {
        let diff = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0);
        if diff == 0 {
            let g = (b.iter().map(|&v| v as u32).sum::<u32>() / channels as u32 / 4) as u8;
            out.extend([g, g, g]);
        } else {
            out.extend([(128 + diff as u32 / 2).min(255) as u8, 0, 0]);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn difference_image_marks_differing_pixels_red() {
        let golden = [100u8, 100, 100, 40, 40, 40];
        let rtl = [100u8, 100, 100, 40, 41, 40];
        assert_eq!(difference_image(&rtl, &golden, 3), vec![25, 25, 25, 128, 0, 0]);
        assert_eq!(difference_image(&[0, 255], &[0, 0], 1), vec![0, 0, 0, 255, 0, 0]);
        assert_eq!(spec_level(0), 0);
        assert_eq!(spec_level(127), 0);
        assert_eq!(spec_level(128), 1);
        assert_eq!(spec_level(u16::MAX), 256);
    }
}
