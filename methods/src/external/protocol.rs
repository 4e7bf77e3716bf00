//! The messages of the external-method protocol, version [`VERSION`] (README "Adding a method in
//! another language" documents it for method authors).
//!
//! One JSON object per line, UTF-8, each way: the harness writes a request to the program's stdin
//! and reads exactly one answer line from its stdout; stderr is free for the program's own log.
//! Numbers are JSON numbers: serde_json writes every f64 in its shortest round-trip form (as do
//! Python's `json`, JavaScript's `JSON.stringify` and C++'s `std::to_chars`), so positions cross
//! the pipe exactly, bit for bit. NaN and infinities are not JSON; an answer holding them is an
//! error.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The protocol's name, sent in `hello` and expected back.
pub const PROTOCOL: &str = "deformbench-method";
/// The protocol version this harness speaks.
pub const VERSION: u32 = 1;

/// What the harness asks, one per line.
#[derive(Debug, Serialize)]
#[serde(tag = "request", rename_all = "snake_case")]
pub enum Request<'a> {
    /// First message of a process: the protocol and the method's parameters (its `params` table of
    /// `configs/methods.toml`, untouched).
    Hello { protocol: &'static str, version: u32, method: &'a str, params: &'a serde_json::Value },
    /// Handle-independent work on the rest mesh (`#V x 3` positions, `#F x 3` vertex indices,
    /// 0-based, counter-clockwise seen from outside); resets the current shape to the rest shape.
    Precompute { vertices: &'a [[f64; 3]], faces: &'a [[u32; 3]] },
    /// A handle set: disjoint regions of vertex indices, each moved as a unit. Keeps the current
    /// shape (a second `bind` in a multi-step scenario continues from the last result).
    Bind { regions: Vec<&'a [u32]> },
    /// Targets of every constrained vertex (`constrained[i]` goes to `targets[i]`; the regions'
    /// vertices in region order); solve from the current shape.
    Solve { constrained: &'a [u32], targets: &'a [[f64; 3]] },
    /// The last message: the program should exit (stdin is closed after it).
    Quit,
}

/// One answer line. Only `ok` is required; `error` when it is false; `positions` for `solve`.
#[derive(Debug, Default, Deserialize)]
pub struct Answer {
    pub ok: bool,
    #[serde(default)]
    pub error: Option<String>,
    /// `hello`: the protocol name and version the program speaks.
    #[serde(default)]
    pub protocol: Option<String>,
    #[serde(default, deserialize_with = "whole_number")]
    pub version: Option<u32>,
    /// `hello`: free text on what runs (e.g. "libigl 2.6.3 arap, SPOKES energy"), shown in reports.
    #[serde(default)]
    pub about: Option<String>,
    /// `solve`: the result, `#V x 3`.
    #[serde(default)]
    pub positions: Option<Vec<[f64; 3]>>,
    /// `solve`: the method's own iteration count, convergence flag and last step (over the rest
    /// bounding-box diagonal). Without `converged` the solve counts as finished (a direct method, or
    /// one that cannot tell).
    #[serde(default, deserialize_with = "whole_number")]
    pub iterations: Option<usize>,
    #[serde(default)]
    pub converged: Option<bool>,
    #[serde(default)]
    pub final_step: Option<f64>,
    /// `solve`, optional: the method's own estimate of its answer's distance to its fixed point
    /// (over the rest bounding-box diagonal), as the built-in methods report theirs.
    #[serde(default)]
    pub distance: Option<f64>,
    /// Any request: the method's own timings of that request, seconds by name.
    #[serde(default)]
    pub timings: BTreeMap<String, f64>,
    /// `precompute` or `bind`: sizes of a reduced model (counts), by name.
    #[serde(default)]
    pub statistics: BTreeMap<String, f64>,
    /// `solve`: one entry per iteration.
    #[serde(default)]
    pub trace: Vec<TraceEntry>,
}

/// A count: a JSON integer, or a number with an integral value (`300.0`, as a language without an
/// integer type writes it); a fraction or a negative number is an error.
fn whole_number<'de, D, T>(deserializer: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: TryFrom<u64>,
{
    let Some(value) = Option::<f64>::deserialize(deserializer)? else { return Ok(None) };
    if value.fract() != 0.0 || !(0.0..=9.007_199_254_740_992e15).contains(&value) {
        return Err(serde::de::Error::custom(format!("{value} is not a count (a whole number >= 0)")));
    }
    T::try_from(value as u64).map(Some).map_err(|_| serde::de::Error::custom(format!("{value} is too large")))
}

/// One iteration of a `solve` as the method reports it.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct TraceEntry {
    /// Largest vertex displacement of the iteration over the rest bounding-box diagonal.
    pub step: f64,
    /// Wall seconds of the iteration.
    pub seconds: f64,
}

/// One request as a line (with its `\n`).
pub fn encode(request: &Request<'_>) -> String {
    let mut line = serde_json::to_string(request).expect("requests hold only finite numbers and strings");
    line.push('\n');
    line
}

/// Parse one answer line; the error says what is wrong with it, in the words of a method author.
pub fn decode(line: &str) -> Result<Answer, String> {
    let text = line.trim_end();
    if text.is_empty() {
        return Err("answered an empty line".into());
    }
    serde_json::from_str::<Answer>(text).map_err(|e| {
        let token_at = text.get(e.column().saturating_sub(1)..).unwrap_or("");
        if ["NaN", "Infinity", "-Infinity", "inf", "-inf", "nan"].iter().any(|t| token_at.starts_with(t)) {
            format!(
                "answered a non-finite number ({}) at column {}: NaN and infinities are not JSON and no \
                 position may be one",
                &token_at[..token_at.find([',', ']', '}']).unwrap_or(token_at.len()).min(9)],
                e.column()
            )
        } else if e.is_eof() {
            format!(
                "answered a line that ends inside a JSON value: an answer is one line (print it without \
                 indentation or line breaks); the line was: {}",
                excerpt(text)
            )
        } else {
            format!(
                "answered a line that is not a protocol answer ({}); around column {}: {}",
                e.to_string().split(" at line ").next().unwrap_or_default(),
                e.column(),
                around(text, e.column())
            )
        }
    })
}

/// The text of `line` around 1-based `column` (60 characters either side, `⟨here⟩` at the column),
/// so an error in a long answer quotes the place, not the line's start.
pub fn around(line: &str, column: usize) -> String {
    const SIDE: usize = 60;
    let at = line.char_indices().map(|(i, _)| i).nth(column.saturating_sub(1)).unwrap_or(line.len());
    let start = line[..at].char_indices().rev().nth(SIDE - 1).map_or(0, |(i, _)| i);
    let end = line[at..].char_indices().nth(SIDE).map_or(line.len(), |(i, _)| at + i);
    format!(
        "{}{}⟨here⟩{}{}",
        if start > 0 { "…" } else { "" },
        &line[start..at],
        &line[at..end],
        if end < line.len() { "…" } else { "" }
    )
}

/// The start of a long line, for error messages.
pub fn excerpt(text: &str) -> String {
    const LIMIT: usize = 120;
    match text.char_indices().nth(LIMIT) {
        Some((at, _)) => format!("{}…", &text[..at]),
        None => text.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_cross_the_pipe_bit_for_bit() {
        let vertices = [[0.1, 1.0 / 3.0, -2.0f64.sqrt()], [f64::MIN_POSITIVE, 1e300, -5e-324]];
        let line = encode(&Request::Precompute { vertices: &vertices, faces: &[[0, 1, 1]] });
        let value: serde_json::Value = serde_json::from_str(&line).unwrap();
        let back: Vec<[f64; 3]> = serde_json::from_value(value["vertices"].clone()).unwrap();
        for (a, b) in vertices.iter().flatten().zip(back.iter().flatten()) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    #[test]
    fn requests_are_tagged_by_name() {
        let params = serde_json::json!({"k": 2});
        let hello =
            encode(&Request::Hello { protocol: PROTOCOL, version: VERSION, method: "m", params: &params });
        assert_eq!(
            hello,
            "{\"request\":\"hello\",\"protocol\":\"deformbench-method\",\"version\":1,\"method\":\"m\",\"params\":{\"k\":2}}\n"
        );
        assert_eq!(encode(&Request::Quit), "{\"request\":\"quit\"}\n");
        let bind = encode(&Request::Bind { regions: vec![&[0, 1], &[5]] });
        assert_eq!(bind, "{\"request\":\"bind\",\"regions\":[[0,1],[5]]}\n");
    }

    #[test]
    fn a_nan_is_named_and_other_garbage_is_quoted() {
        let nan = decode("{\"ok\": true, \"positions\": [[0.0, NaN, 1.0]]}").unwrap_err();
        assert!(nan.contains("non-finite number (NaN)"), "{nan}");
        let garbage = decode("hello from my method").unwrap_err();
        assert!(
            garbage.contains("not a protocol answer") && garbage.contains("hello from my method"),
            "{garbage}"
        );
        assert!(decode("").unwrap_err().contains("empty line"));
        let wrong = decode("{\"ok\": true, \"positions\": [[0.0, 1.0]]}").unwrap_err();
        assert!(wrong.contains("not a protocol answer"), "{wrong}");
        let answer = decode("{\"ok\": true, \"iterations\": 3, \"extra\": 1}").unwrap();
        assert!(answer.ok && answer.iterations == Some(3));
    }

    /// Issue 38: counts may be integral floats; a fraction is named with the place it is at, deep
    /// in a long line; an answer spread over lines (pretty-printed) is named as such.
    #[test]
    fn counts_may_be_integral_floats_and_errors_quote_their_place() {
        let answer = decode("{\"ok\": true, \"iterations\": 300.0, \"version\": 1.0}").unwrap();
        assert_eq!((answer.iterations, answer.version), (Some(300), Some(1)));
        let positions = vec!["[0.5, 0.25, 1.0]"; 5000].join(", ");
        let line = format!("{{\"ok\": true, \"positions\": [{positions}], \"iterations\": 300.5}}");
        let err = decode(&line).unwrap_err();
        assert!(err.contains("300.5 is not a count"), "{err}");
        assert!(err.contains("\"iterations\": 300.5") && err.contains("⟨here⟩"), "quotes the place: {err}");
        assert!(err.len() < 400, "not the whole line: {} characters", err.len());
        let err = decode("{").unwrap_err();
        assert!(err.contains("one line"), "{err}");
        let err = decode("{\"ok\": true, \"iterations\": -3}").unwrap_err();
        assert!(err.contains("not a count"), "{err}");
    }
}
