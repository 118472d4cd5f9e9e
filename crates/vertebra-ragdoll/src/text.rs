//! Reading and writing the TOML files (ragdolls and skeletons): a file
//! read whole within a size cap, parse errors by line, and numbers and
//! names written so that reading them back gives the same bits.

use std::io::Read;
use std::path::Path;

use crate::error::RagdollError;

/// The largest ragdoll, generator or skeleton text the loaders take
/// (bytes), from a file (`from_file`, `check_file`) or a string
/// (`from_toml`, `check_toml`, and the C ABI's string functions): the
/// reference humanoid is 5 KB and a body, joint or bone about 150 bytes, so
/// 1 MiB holds thousands. A longer text is refused before it is parsed
/// ([`RagdollError::TooLarge`]), a longer file before it is opened. Only
/// regular files are read: a pipe, a device (`/dev/zero`, `/dev/stdin`) or
/// a directory is refused without opening it (opening a pipe waits for a
/// writer, for ever).
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// Refuses a `file` text (`ragdoll`, `generator` or `skeleton`) of
/// `bytes` bytes longer than [`MAX_FILE_BYTES`]: the one check every
/// loader makes of its text, a file's or a string's, before it parses it.
pub(crate) fn within_cap(bytes: u64, file: &'static str) -> Result<(), RagdollError> {
    if bytes <= MAX_FILE_BYTES {
        Ok(())
    } else {
        Err(RagdollError::TooLarge {
            file,
            limit: MAX_FILE_BYTES,
        })
    }
}

/// The UTF-8 text of the `file` file (`ragdoll`, `generator` or
/// `skeleton`, which the errors name) at `path`: the one reader of every
/// file the loaders (and `vertebra`) read. The file's type and size are
/// checked before it is opened: anything but a regular file (a FIFO, a
/// device, a directory) is refused without opening it, and so is a file
/// longer than [`MAX_FILE_BYTES`]; both are checked again on what was
/// opened, and at most `MAX_FILE_BYTES + 1` bytes are read. Every error
/// names the file.
pub fn read_text(path: &Path, file: &'static str) -> Result<String, RagdollError> {
    let unreadable = |reason: String| in_file(path, RagdollError::Unreadable { file, reason });
    let regular = |meta: std::fs::Metadata| {
        if !meta.is_file() {
            return Err(unreadable(
                "not a regular file (a directory, a device or a pipe)".to_owned(),
            ));
        }
        within_cap(meta.len(), file).map_err(|e| in_file(path, e))
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
    // And on what was read, in case the file grew since.
    within_cap(bytes.len() as u64, file).map_err(|e| in_file(path, e))?;
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
