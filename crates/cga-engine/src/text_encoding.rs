//! How the bytes of a rule file (or of a text file a rule reads) become
//! text. CityEngine saves rule files in the platform's encoding, so real
//! files come as UTF-8 and as Windows-1252 (German umlauts, degree signs in
//! comments and strings): a byte order mark decides first (UTF-8, UTF-16),
//! then UTF-8 if the bytes are valid UTF-8, else Windows-1252, which maps
//! every byte to a character. No file is ever rejected for its encoding.

/// Which encoding [`decode`] read the bytes as.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SourceEncoding {
    Utf8,
    /// UTF-16 (little or big endian), told by its byte order mark.
    Utf16,
    Windows1252,
}

/// The text of `bytes` (a byte order mark removed) and the encoding used.
pub fn decode(bytes: &[u8]) -> (String, SourceEncoding) {
    if let Some((encoding, bom)) = encoding_rs::Encoding::for_bom(bytes) {
        let rest = &bytes[bom..];
        let (text, _) = encoding.decode_without_bom_handling(rest);
        let which = if encoding == encoding_rs::UTF_8 {
            SourceEncoding::Utf8
        } else {
            SourceEncoding::Utf16
        };
        return (text.into_owned(), which);
    }
    match std::str::from_utf8(bytes) {
        Ok(text) => (text.to_string(), SourceEncoding::Utf8),
        Err(_) => {
            let (text, _) = encoding_rs::WINDOWS_1252.decode_without_bom_handling(bytes);
            (text.into_owned(), SourceEncoding::Windows1252)
        }
    }
}

/// Reads a file as text with [`decode`].
pub fn read_text(path: &std::path::Path) -> std::io::Result<String> {
    std::fs::read(path).map(|bytes| decode(&bytes).0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utf8_windows_1252_and_byte_order_marks() {
        assert_eq!(
            decode("Höhe 20°".as_bytes()),
            ("Höhe 20°".to_string(), SourceEncoding::Utf8)
        );
        // The same text saved as Windows-1252: 0xF6 is ö, 0xB0 the degree sign.
        assert_eq!(
            decode(b"H\xf6he 20\xb0 \x80"),
            ("Höhe 20° €".to_string(), SourceEncoding::Windows1252)
        );
        assert_eq!(
            decode(b"\xEF\xBB\xBFattr a = 1"),
            ("attr a = 1".to_string(), SourceEncoding::Utf8)
        );
        assert_eq!(
            decode(b"\xFF\xFEa\0=\x001\0"),
            ("a=1".to_string(), SourceEncoding::Utf16)
        );
    }
}
