//! What a file is, from its first bytes (magic numbers), not its name: text, gzip, a workbook,
//! Parquet, or something this tool does not read, said in words with what to do instead.

use super::table::Table;
use super::{sheet, text, ReadOptions};
use anyhow::{bail, Result};
use std::io::Read;
use std::path::Path;

/// The kinds of file the bytes can be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Text,
    Gzip,
    /// A workbook (or a zip or Office file that may be one); the words for messages.
    Workbook(&'static str),
    Parquet,
    /// Something else: what it is, and what to do.
    Other(&'static str, &'static str),
}

/// The format of a file from its first bytes.
pub fn sniff(bytes: &[u8]) -> Format {
    let starts = |magic: &[u8]| bytes.starts_with(magic);
    if starts(&[0x1f, 0x8b]) {
        return Format::Gzip;
    }
    if starts(b"PK\x03\x04") {
        return sniff_zip(bytes);
    }
    if starts(&[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1]) {
        return Format::Workbook("Excel 97-2003 workbook");
    }
    if starts(b"PAR1") {
        return Format::Parquet;
    }
    for (magic, what, todo) in OTHERS {
        if starts(magic) {
            return Format::Other(what, todo);
        }
    }
    sniff_text(bytes)
}

/// Magic numbers of files this tool does not read: what each is, and what to do instead.
const OTHERS: &[(&[u8], &str, &str)] = &[
    (
        b"%PDF",
        "a PDF document",
        "export the data from its source as CSV",
    ),
    (
        b"\x89PNG",
        "a PNG image",
        "give the data file, not a picture of it",
    ),
    (
        b"\xFF\xD8\xFF",
        "a JPEG image",
        "give the data file, not a picture of it",
    ),
    (
        b"GIF8",
        "a GIF image",
        "give the data file, not a picture of it",
    ),
    (
        b"BZh",
        "a bzip2-compressed file",
        "decompress it first (bunzip2 FILE) or compress it with gzip",
    ),
    (
        b"\xFD7zXZ\x00",
        "an xz-compressed file",
        "decompress it first (unxz FILE) or compress it with gzip",
    ),
    (
        b"7z\xBC\xAF\x27\x1C",
        "a 7-Zip archive",
        "unpack it and give the CSV inside",
    ),
    (
        b"\x28\xB5\x2F\xFD",
        "a zstd-compressed file",
        "decompress it first (unzstd FILE) or compress it with gzip",
    ),
    (
        b"\x89HDF",
        "an HDF5 file",
        "export the loop's columns as CSV or Parquet",
    ),
    (
        b"SQLite format 3\x00",
        "an SQLite database",
        "export the loop's table as CSV",
    ),
    (
        b"ARROW1",
        "an Arrow IPC (Feather) file",
        "write it as Parquet or CSV",
    ),
];

/// A zip archive: an OpenDocument or Excel workbook, another Office document, or a plain zip.
fn sniff_zip(bytes: &[u8]) -> Format {
    let head = &bytes[..bytes.len().min(200)];
    if contains(head, b"application/vnd.oasis.opendocument.spreadsheet") {
        return Format::Workbook("OpenDocument spreadsheet");
    }
    if contains(head, b"application/vnd.oasis.opendocument") {
        return Format::Other(
            "an OpenDocument file, not a spreadsheet",
            "save the data as CSV, xlsx or ods",
        );
    }
    if contains(bytes, b"xl/") {
        return Format::Workbook("Excel workbook");
    }
    if contains(bytes, b"word/") || contains(bytes, b"ppt/") {
        return Format::Other(
            "a Word or PowerPoint document",
            "save the data as CSV or an xlsx workbook",
        );
    }
    Format::Workbook("zip archive")
}

/// Text that is not a table (HTML, XML spreadsheets, JSON), binary data, or a table.
fn sniff_text(bytes: &[u8]) -> Format {
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(2048)]).to_ascii_lowercase();
    let head = head.trim_start_matches('\u{feff}').trim_start();
    if head.starts_with("<?xml") && head.contains("urn:schemas-microsoft-com:office:spreadsheet") {
        return Format::Other(
            "an Excel 2003 XML spreadsheet",
            "open it in a spreadsheet and save it as xlsx or CSV",
        );
    }
    if head.starts_with('<') && (head.contains("<html") || head.contains("<table")) {
        return Format::Other(
            "an HTML page (some historians save HTML tables under an .xls name)",
            "open it in a spreadsheet and save it as xlsx or CSV",
        );
    }
    if head.starts_with("{\"") || head.starts_with("[{") {
        return Format::Other("JSON, not a table", "export the loop's columns as CSV");
    }
    let utf16 = bytes.starts_with(&[0xFF, 0xFE]) || bytes.starts_with(&[0xFE, 0xFF]);
    if !utf16 && bytes[..bytes.len().min(8192)].contains(&0) {
        return Format::Other(
            "a binary file, not text",
            "give a CSV, xlsx, xls, ods, Parquet or gzip-compressed CSV file",
        );
    }
    Format::Text
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

/// A table from a file's bytes in whatever format they are. `depth` counts nested gzip layers.
pub fn parse(path: &Path, bytes: &[u8], opts: &ReadOptions, depth: u8) -> Result<Table> {
    let file = path.display();
    let format = sniff(bytes);
    if opts.sheet.is_some() && !matches!(format, Format::Workbook(_) | Format::Gzip) {
        bail!(
            "{file}: --sheet applies to workbooks (xlsx, xls, ods) and this is {}; leave --sheet out",
            words(format)
        );
    }
    match format {
        Format::Gzip if depth > 0 => bail!(
            "{file}: this is gzip inside gzip; decompress it once (gunzip FILE) and read that"
        ),
        Format::Gzip => {
            let mut out = Vec::new();
            if let Err(e) = flate2::read::MultiGzDecoder::new(bytes).read_to_end(&mut out) {
                bail!("{file}: this is a gzip file that cannot be decompressed ({e}); check the file is complete");
            }
            parse(path, &out, opts, depth + 1)
        }
        Format::Workbook(kind) => guarded(path, kind, || sheet::read(path, bytes, opts, kind)),
        Format::Parquet => guarded(path, "Parquet file", || parquet(path, bytes)),
        Format::Other(what, todo) => bail!("{file}: this is {what}; {todo}"),
        Format::Text => text::read(path, &text::decode(bytes)),
    }
}

thread_local! {
    /// Set while a third-party reader runs on untrusted bytes: its panic is caught and said as
    /// a sentence, so the panic hook stays quiet.
    static GUARDED: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether a panic now is a reader's on a damaged file, caught by [`guarded`].
pub fn in_guarded_reader() -> bool {
    GUARDED.with(|g| g.get())
}

/// Run a workbook or Parquet reader; a panic in it (damaged bytes) becomes one sentence.
fn guarded(path: &Path, kind: &str, read: impl FnOnce() -> Result<Table>) -> Result<Table> {
    GUARDED.with(|g| g.set(true));
    let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read));
    GUARDED.with(|g| g.set(false));
    r.unwrap_or_else(|_| {
        bail!(
            "{}: this looks like an {kind} but it is damaged and cannot be read; save it again, or export CSV",
            path.display()
        )
    })
}

fn words(f: Format) -> &'static str {
    match f {
        Format::Text => "a text file",
        Format::Parquet => "a Parquet file",
        Format::Other(what, _) => what,
        Format::Gzip | Format::Workbook(_) => "a workbook",
    }
}

#[cfg(feature = "parquet")]
fn parquet(path: &Path, bytes: &[u8]) -> Result<Table> {
    super::parquet::read(path, bytes)
}

#[cfg(not(feature = "parquet"))]
fn parquet(path: &Path, _bytes: &[u8]) -> Result<Table> {
    bail!(
        "{}: this is a Parquet file, and this build of stiction reads none (it was built without the 'parquet' feature); \
         install it with default features, or export CSV",
        path.display()
    )
}
