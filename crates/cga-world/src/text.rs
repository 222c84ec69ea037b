//! Decoding text files as CityEngine writes them.
//!
//! CityEngine saves rule files and tables in the platform's encoding:
//! UTF-8 on recent versions, Windows-1252 (Latin-1 with the typographic
//! characters) on older Windows installations, where umlauts, degree signs
//! and accented letters appear in comments and strings. A file is read as
//! UTF-8 when it is valid UTF-8, else as Windows-1252; a byte-order mark
//! (UTF-8 or UTF-16) says the encoding outright and is dropped. No file is
//! refused for its encoding.

use std::borrow::Cow;

/// The text of a file's bytes (see the module documentation).
pub fn decode_text(bytes: &[u8]) -> String {
    if let Some((encoding, bom)) = encoding_rs::Encoding::for_bom(bytes) {
        let (text, _) = encoding.decode_without_bom_handling(&bytes[bom..]);
        return text.into_owned();
    }
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_owned(),
        Err(_) => {
            let (text, _, _) = encoding_rs::WINDOWS_1252.decode(bytes);
            match text {
                Cow::Borrowed(s) => s.to_owned(),
                Cow::Owned(s) => s,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf8_is_read_as_utf8() {
        assert_eq!(decode_text("Höhe 20°".as_bytes()), "Höhe 20°");
    }

    #[test]
    fn other_bytes_are_windows_1252() {
        // "Höhe 20°" and a euro sign as Windows-1252 writes them.
        let bytes = [b'H', 0xF6, b'h', b'e', b' ', b'2', b'0', 0xB0, b' ', 0x80];
        assert_eq!(decode_text(&bytes), "Höhe 20° €");
    }

    #[test]
    fn a_byte_order_mark_decides_and_is_dropped() {
        let mut utf8 = vec![0xEF, 0xBB, 0xBF];
        utf8.extend_from_slice("attr ä = 1".as_bytes());
        assert_eq!(decode_text(&utf8), "attr ä = 1");
        let utf16: Vec<u8> = [0xFF, 0xFE]
            .into_iter()
            .chain("Lot".encode_utf16().flat_map(u16::to_le_bytes))
            .collect();
        assert_eq!(decode_text(&utf16), "Lot");
    }
}
