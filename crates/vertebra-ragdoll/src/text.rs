//! Reading and writing the TOML files (ragdolls and skeletons): a file
//! read whole within a size cap, parse errors by line, and numbers and
//! names written so that reading them back gives the same bits.

use std::io::Read;
use std::path::Path;

use crate::error::RagdollError;

/// The largest ragdoll or skeleton file that `from_file` reads (bytes): the
/// reference humanoid is 5 KB and a body, joint or bone about 150 bytes,
/// so 1 MiB holds thousands; a larger file is refused before it is read
/// whole. Only regular files are read: a pipe, a device (`/dev/zero`,
/// `/dev/stdin`) or a directory is refused without opening it (opening a
/// pipe waits for a writer, for ever).
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// The UTF-8 text of the `file` file (`ragdoll` or `skeleton`) at `path`,
/// at most [`MAX_FILE_BYTES`]; the error names the file.
pub(crate) fn read_text(path: &Path, file: &'static str) -> Result<String, RagdollError> {
    let unreadable = |reason: String| RagdollError::File {
        path: path.display().to_string(),
        error: Box::new(RagdollError::Unreadable { file, reason }),
    };
    let regular = |meta: std::fs::Metadata| {
        if meta.is_file() {
            Ok(())
        } else {
            Err(unreadable(
                "not a regular file (a directory, a device or a pipe)".to_owned(),
            ))
        }
    };
    regular(std::fs::metadata(path).map_err(|e| unreadable(e.to_string()))?)?;
    let opened = std::fs::File::open(path).map_err(|e| unreadable(e.to_string()))?;
    // Checked again on what was opened, in case the path changed between.
    regular(opened.metadata().map_err(|e| unreadable(e.to_string()))?)?;
    let mut bytes = Vec::new();
    opened
        .take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| unreadable(e.to_string()))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(unreadable(format!(
            "larger than {MAX_FILE_BYTES} bytes; a {file} file is a few KB"
        )));
    }
    String::from_utf8(bytes).map_err(|e| {
        unreadable(format!(
            "not UTF-8 text (at byte {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

/// `error`, said of the file at `path`.
pub(crate) fn in_file(path: &Path, error: RagdollError) -> RagdollError {
    RagdollError::File {
        path: path.display().to_string(),
        error: Box::new(error),
    }
}

/// Where a text's lines end, to name the line of a byte offset.
pub(crate) struct Lines(Vec<usize>);

impl Lines {
    pub(crate) fn new(text: &str) -> Self {
        Self(text.match_indices('\n').map(|(at, _)| at).collect())
    }

    /// The line (from 1) of byte `offset`.
    pub(crate) fn at(&self, offset: usize) -> usize {
        self.0.partition_point(|&end| end < offset) + 1
    }
}

/// A parse error of a `file` file on one line: where, and what (without
/// the source excerpt).
pub(crate) fn syntax(file: &'static str, lines: &Lines, e: &toml::de::Error) -> RagdollError {
    let message = e.message().split_whitespace().collect::<Vec<_>>().join(" ");
    let message = match e.span() {
        Some(span) => format!("line {}: {message}", lines.at(span.start)),
        None => message,
    };
    RagdollError::Syntax { file, message }
}

/// An item's name in an error: `what`, after its line when it has one
/// (`line 12: body `hips``).
pub(crate) fn item(line: Option<usize>, what: &str) -> String {
    match line {
        Some(line) => format!("line {line}: {what}"),
        None => what.to_owned(),
    }
}

/// `x` as TOML that reads back as the same bits: Rust's shortest
/// round-trip form, unless reading it as `f64` and rounding to `f32` (as
/// the TOML parser does) would land on a neighbour, then the exact `f64`
/// value; `inf`, `-inf` and `nan` as TOML spells them.
pub(crate) fn float(x: f32) -> String {
    if x.is_nan() {
        return "nan".to_owned();
    }
    let short = format!("{x:?}");
    if !x.is_finite() || short.parse::<f64>().map(|v| v as f32).map(f32::to_bits) == Ok(x.to_bits())
    {
        short
    } else {
        format!("{:?}", f64::from(x))
    }
}

/// `[a, b, c]` of [`float`]s.
pub(crate) fn floats(values: &[f32]) -> String {
    let inner: Vec<String> = values.iter().map(|&v| float(v)).collect();
    format!("[{}]", inner.join(", "))
}

/// `s` as a TOML basic string.
pub(crate) fn string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => out.push_str(&format!("\\u{:04X}", u32::from(c))),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Whether `a` and `b` have the same bits (`-0.0` and `0.0` differ).
pub(crate) fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}
