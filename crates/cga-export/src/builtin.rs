//! CGA's built-in textures, generated here as PNG images.
//!
//! Rules name them `builtin:default` (a 16 x 16 black and white
//! checkerboard) and `builtin:uvtest.png` (a texture coordinate test
//! pattern). They are not files anywhere: the exporter generates them once
//! per process and embeds them in GLB files or writes them next to OBJ and
//! glTF output as `builtin_default.png` and `builtin_uvtest.png`.
//!
//! The test pattern makes texture coordinates readable on a model: red
//! grows with u (left to right), green with v (bottom to top), and an 8 x 8
//! grid of cells alternates blue so that tiling and mirroring show. The
//! cell at u, v in [0, 1/8] (bottom left) is white, marking the origin.

use std::sync::{Arc, OnceLock};

/// Prefix of built-in texture names.
pub const PREFIX: &str = "builtin:";

/// A built-in texture: the file name it is written under and its PNG bytes.
pub struct BuiltinTexture {
    pub file_name: &'static str,
    pub png: Arc<[u8]>,
}

/// The built-in texture `name` (with its `builtin:` prefix), or `None` if
/// CGA has no such built-in texture.
pub fn builtin_texture(name: &str) -> Option<BuiltinTexture> {
    static DEFAULT: OnceLock<Arc<[u8]>> = OnceLock::new();
    static UVTEST: OnceLock<Arc<[u8]>> = OnceLock::new();
    match name.strip_prefix(PREFIX)? {
        "default" => Some(BuiltinTexture {
            file_name: "builtin_default.png",
            png: DEFAULT.get_or_init(checkerboard).clone(),
        }),
        "uvtest.png" => Some(BuiltinTexture {
            file_name: "builtin_uvtest.png",
            png: UVTEST.get_or_init(uv_test).clone(),
        }),
        _ => None,
    }
}

/// 16 x 16 squares of 8 x 8 pixels, black and white, grey-scale.
fn checkerboard() -> Arc<[u8]> {
    const N: u32 = 128;
    let pixels: Vec<u8> = (0..N * N)
        .map(|i| {
            let (x, y) = (i % N / 8, i / N / 8);
            if (x + y) % 2 == 0 {
                255
            } else {
                0
            }
        })
        .collect();
    encode(N, N, png::ColorType::Grayscale, &pixels)
}

/// The uv test pattern (see the module docs), 256 x 256 RGB.
fn uv_test() -> Arc<[u8]> {
    const N: u32 = 256;
    const CELL: u32 = N / 8;
    let mut pixels = Vec::with_capacity((N * N * 3) as usize);
    for row in 0..N {
        // Image rows run from the top; v runs from the bottom.
        let y = N - 1 - row;
        for x in 0..N {
            let (cx, cy) = (x / CELL, y / CELL);
            // Grid lines on the first pixel of each cell (CELL is a power of two).
            let line = x & (CELL - 1) == 0 || y & (CELL - 1) == 0;
            let rgb = if line {
                [32, 32, 32]
            } else if cx == 0 && cy == 0 {
                [255, 255, 255]
            } else {
                let blue = if (cx + cy) % 2 == 0 { 64 } else { 200 };
                [x as u8, y as u8, blue]
            };
            pixels.extend_from_slice(&rgb);
        }
    }
    encode(N, N, png::ColorType::Rgb, &pixels)
}

fn encode(w: u32, h: u32, color: png::ColorType, pixels: &[u8]) -> Arc<[u8]> {
    let mut bytes = Vec::new();
    let mut enc = png::Encoder::new(&mut bytes, w, h);
    enc.set_color(color);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::Best);
    // Writing into memory cannot fail, and the pixel count matches the
    // header by construction.
    let written = enc
        .write_header()
        .and_then(|mut wr| wr.write_image_data(pixels));
    debug_assert!(written.is_ok(), "{written:?}");
    Arc::from(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(bytes: &[u8]) -> (png::OutputInfo, Vec<u8>) {
        let mut r = png::Decoder::new(bytes).read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    #[test]
    fn checkerboard_has_16_squares_a_side() {
        let t = builtin_texture("builtin:default").unwrap();
        assert_eq!(t.file_name, "builtin_default.png");
        let (info, px) = decode(&t.png);
        assert_eq!((info.width, info.height), (128, 128));
        assert_eq!(info.color_type, png::ColorType::Grayscale);
        // Along the first row the colour changes every 8 pixels: 16 squares.
        let changes = px[..128].windows(2).filter(|w| w[0] != w[1]).count();
        assert_eq!(changes, 15);
        assert_eq!(px[0], 255);
        assert_eq!(px[8], 0);
        assert_eq!(px[128 * 8], 0);
    }

    #[test]
    fn uv_test_colours_follow_u_and_v() {
        let t = builtin_texture("builtin:uvtest.png").unwrap();
        let (info, px) = decode(&t.png);
        assert_eq!((info.width, info.height), (256, 256));
        let at = |x: usize, row: usize| {
            let i = (row * 256 + x) * 3;
            [px[i], px[i + 1], px[i + 2]]
        };
        // Red = u, green = v (row 0 is the top, v = 1).
        assert_eq!(at(200, 10)[..2], [200, 245]);
        assert_eq!(at(100, 200)[..2], [100, 55]);
        // The origin cell (bottom left) is white.
        assert_eq!(at(10, 250), [255, 255, 255]);
    }

    #[test]
    fn unknown_names_are_not_builtin() {
        assert!(builtin_texture("builtin:nothing.png").is_none());
        assert!(builtin_texture("default").is_none());
    }
}
