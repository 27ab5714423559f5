//! Plain PPM (P3) text, byte for byte as the `image` crate's `PnmEncoder` writes it,
//! at a few instructions a sample instead of a `write!` through `core::fmt` each
//! (about 220: a 1280×720 image took 0.1 s to write, three times its render).
//!
//! The crate's text: the header `P3\n{width} {height} 255\n`, then each sample as its
//! decimal digits and one space, given to a line breaker as two pieces (the digits,
//! then the space) that starts a new line before a piece that would take a non-empty
//! line past 70 bytes. A line may therefore begin with a space, and the text ends
//! without a newline. Decoders accept it; the tests hold it to the crate's bytes.

use std::io::{self, Write};

/// The longest line, as the crate and the format's description have it.
const LINE: usize = 70;

/// Bytes of text gathered before each write to the output.
const CHUNK: usize = 1 << 16;

/// The digits of every byte value, left-aligned in three bytes, and their count.
const DIGITS: [([u8; 3], u8); 256] = {
    let mut table = [([0u8; 3], 0u8); 256];
    let mut v = 0;
    while v < 256 {
        let (hundreds, tens, ones) = (v / 100, v / 10 % 10, v % 10);
        table[v] = if v >= 100 {
            (
                [b'0' + hundreds as u8, b'0' + tens as u8, b'0' + ones as u8],
                3,
            )
        } else if v >= 10 {
            ([b'0' + tens as u8, b'0' + ones as u8, 0], 2)
        } else {
            ([b'0' + ones as u8, 0, 0], 1)
        };
        v += 1;
    }
    table
};

/// Writes 8-bit RGB samples `raw` (top row first, `width` × `height` pixels) to `out`
/// as plain PPM text.
pub(super) fn write(raw: &[u8], width: u32, height: u32, out: &mut dyn Write) -> io::Result<()> {
    out.write_all(format!("P3\n{width} {height} 255\n").as_bytes())?;
    // A sample adds at most five bytes (a newline, three digits, a space; two
    // newlines never meet, a line being longer than a sample): each goes into the
    // chunk's room in fixed-size copies, the length advanced by what counts.
    let mut text = vec![0u8; CHUNK + 8];
    let mut len = 0;
    // Bytes on the current line since its start.
    let mut column = 0;
    for &sample in raw {
        let (digits, count) = DIGITS[usize::from(sample)];
        let count = usize::from(count);
        if column > 0 && column + count > LINE {
            text[len] = b'\n';
            len += 1;
            column = 0;
        }
        text[len..len + 3].copy_from_slice(&digits);
        len += count;
        column += count;
        if column + 1 > LINE {
            text[len] = b'\n';
            len += 1;
            column = 0;
        }
        text[len] = b' ';
        len += 1;
        column += 1;
        if len >= CHUNK {
            out.write_all(&text[..len])?;
            len = 0;
        }
    }
    out.write_all(&text[..len])?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use image::codecs::pnm::{PnmEncoder, PnmSubtype, SampleEncoding};
    use image::{ExtendedColorType, ImageEncoder};

    fn crate_text(raw: &[u8], width: u32, height: u32) -> Vec<u8> {
        let mut out = Vec::new();
        PnmEncoder::new(&mut out)
            .with_subtype(PnmSubtype::Pixmap(SampleEncoding::Ascii))
            .write_image(raw, width, height, ExtendedColorType::Rgb8)
            .expect("the crate encodes it");
        out
    }

    fn our_text(raw: &[u8], width: u32, height: u32) -> Vec<u8> {
        let mut out = Vec::new();
        super::write(raw, width, height, &mut out).expect("a Vec takes it");
        out
    }

    #[test]
    fn the_text_is_the_image_crate_s_byte_for_byte() {
        // Images of every sample value, of runs of one width of digits (which put
        // the line breaks before a space, before digits and on the 70th byte), and
        // of random bytes; widths whose lines end anywhere; one larger than a chunk.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut random = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 24) as u8
        };
        let sizes = [
            (1, 1),
            (2, 3),
            (7, 5),
            (23, 11),
            (24, 1),
            (70, 3),
            (401, 97),
        ];
        for (width, height) in sizes {
            let n = (width * height * 3) as usize;
            let images: [Vec<u8>; 5] = [
                (0..n).map(|i| i as u8).collect(),
                vec![7; n],
                vec![42; n],
                vec![200; n],
                (0..n).map(|_| random()).collect(),
            ];
            for raw in images {
                let ours = our_text(&raw, width, height);
                assert!(
                    ours == crate_text(&raw, width, height),
                    "{width}x{height} starting {:?}",
                    &raw[..3]
                );
            }
        }
    }

    #[test]
    fn the_text_decodes_to_the_samples() {
        let raw: Vec<u8> = (0..=255).cycle().take(37 * 19 * 3).collect();
        let text = our_text(&raw, 37, 19);
        let decoded = image::load_from_memory(&text).expect("a PPM decoder reads it");
        assert_eq!(decoded.to_rgb8().into_raw(), raw);
        assert!(text.starts_with(b"P3\n37 19 255\n"));
        let longest = text.split(|&b| b == b'\n').map(<[u8]>::len).max();
        assert_eq!(longest, Some(70));
    }
}
