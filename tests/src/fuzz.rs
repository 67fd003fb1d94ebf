//! A seeded, deterministic mutation fuzzer for the pipeline's parsers, with
//! no fuzzing crate: a parser is a function of bytes, and the harness asks
//! only that it return (an `Ok` or an `Err`, either is fine) without a
//! panic and without a hang.
//!
//! # API
//!
//! - [`fuzz`]`(target, seeds, kind, parse)` runs `parse` on
//!   [`cases`]`()` mutants of the seed inputs (a few hundred by default;
//!   `FUZZ_CASES=n` sets it, `make fuzz` sets it high) and panics with a
//!   report of every failure: the target, the case number, the master seed,
//!   what went wrong (the panic message, or "no answer within 5 s"), the
//!   mutations applied and the mutant itself (lossy text, or hex).
//! - A failure replays alone: `FUZZ_REPLAY=<case>` runs only that case of
//!   every target, `FUZZ_SEED=<seed>` changes the master seed (default
//!   [`DEFAULT_SEED`]). Case `k`'s mutant depends only on the seed, `k` and
//!   the seed inputs, never on the other cases or on timing.
//! - A case that aborts the whole process (a stack overflow, an allocation
//!   the system refuses) cannot be caught: `FUZZ_TRACE=1` prints each case
//!   number to stderr before it runs, so the last one printed is the
//!   culprit (run with `--nocapture`).
//! - [`Mutator`] is the mutation engine itself, for a harness of its own:
//!   [`Mutator::for_case`] then [`Mutator::mutate`].
//!
//! ```no_run
//! use end_to_end::fuzz::{fuzz, Kind};
//! fuzz("ron-value", &[b"(a: 1, b: [2.0, 3.0])".as_slice()], Kind::Text, |bytes| {
//!     let _ = std::str::from_utf8(bytes).map(|t| t.parse::<f64>());
//! });
//! ```
//!
//! # Mutations
//!
//! Each case picks one seed input and applies one to four mutations.
//! [`Kind::Text`] inputs get line-level edits (duplicate, remove, swap
//! lines), number replacements (a numeric token becomes `0`, `-1`, `1e308`,
//! `-1e308`, `NaN`, `inf`, `1e-320`, a huge count, an empty token, ...) and
//! byte-level edits; [`Kind::Binary`] inputs get byte-level edits and
//! 4-byte little-endian words replaced by extremes (0, `u32::MAX`,
//! `i32::MAX`, f32 NaN, infinity, a count a little larger than the file).
//! Byte-level edits: flip a bit, delete or duplicate a run of bytes, insert
//! a byte (often a Latin-1 letter, NUL, a newline or a quote), truncate.
//!
//! Fuzz tests are named `fuzz_<target>` so that `make fuzz` can select them
//! all (`cargo test -- fuzz_`).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::mpsc;
use std::time::Duration;

/// Master seed when `FUZZ_SEED` is not set.
pub const DEFAULT_SEED: u64 = 0x5eed_0f11;

/// Cases per target when `FUZZ_CASES` is not set: enough to find the
/// panics issue 11 reports within seconds.
pub const DEFAULT_CASES: usize = 300;

/// How long one case may run before it counts as a hang.
pub const CASE_TIMEOUT: Duration = Duration::from_secs(5);

/// What kind of input a target reads, which decides the mutations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Line-oriented text with numbers (OBJ, MTL, RON, LDT, IES).
    Text,
    /// Binary files (EXR artifacts).
    Binary,
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny, good-enough generator,
/// identical on every platform.
#[derive(Clone, Debug)]
struct SplitMix64(u64);

impl SplitMix64 {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`; the modulo bias is irrelevant here).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Replacements for a number in text: the extremes parsers mishandle.
const EXTREME_NUMBERS: &[&str] = &[
    "0", "-0", "-1", "1", "1e308", "-1e308", "1e309", "NaN", "nan", "inf", "-inf", "1e-320", "4294967295", "4294967296",
    "18446744073709551616", "99999999999", "-2147483649", "0.0000001", "", "1.2.3", "--1", "0x10",
];

/// Bytes worth inserting: Latin-1 letters (not UTF-8), NUL, line breaks,
/// quotes, brackets, a comment sign.
const INTERESTING_BYTES: &[u8] = &[0xe9, 0xff, 0xc3, 0x80, 0x00, b'\n', b'\r', b'"', b'(', b')', b'[', b']', b'#', b' ', b'/', b'-'];

/// Replacements for a 4-byte word in binary input.
const EXTREME_WORDS: &[u32] = &[0, 1, u32::MAX, i32::MAX as u32, 0x8000_0000, 0x7fc0_0000, 0x7f80_0000, 0xff80_0000, 0x7f7f_ffff, 16, 17];

/// The mutation engine of one case.
#[derive(Clone, Debug)]
pub struct Mutator {
    rng: SplitMix64,
    kind: Kind,
}

impl Mutator {
    /// The mutator of case `case` under master seed `seed`.
    pub fn for_case(seed: u64, case: usize, kind: Kind) -> Self {
        let mut rng = SplitMix64(seed ^ (case as u64).wrapping_mul(0xd6e8_feb8_6659_fd93));
        rng.next();
        Mutator { rng, kind }
    }

    /// Picks one of `seeds` (which must not be empty) and mutates it; returns
    /// the mutant and a description of each mutation applied, in order.
    pub fn mutate(&mut self, seeds: &[&[u8]]) -> (Vec<u8>, Vec<String>) {
        let pick = self.rng.below(seeds.len());
        let mut bytes = seeds[pick].to_vec();
        let mut applied = vec![format!("seed input {pick}")];
        for _ in 0..1 + self.rng.below(4) {
            applied.push(self.mutate_once(&mut bytes));
        }
        (bytes, applied)
    }

    fn mutate_once(&mut self, bytes: &mut Vec<u8>) -> String {
        let structural = self.rng.below(3) != 0;
        match (self.kind, structural) {
            (Kind::Text, true) => {
                if self.rng.below(2) == 0 {
                    self.replace_number(bytes)
                } else {
                    self.edit_lines(bytes)
                }
            }
            (Kind::Binary, true) => self.replace_word(bytes),
            (_, false) => self.edit_bytes(bytes),
        }
    }

    /// Replaces one numeric token (a maximal run of digits, signs, dots and
    /// exponents that contains a digit) by an extreme.
    fn replace_number(&mut self, bytes: &mut Vec<u8>) -> String {
        let numeric = |b: u8| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E');
        let mut tokens = Vec::new();
        let mut start = None;
        for (i, &b) in bytes.iter().chain(std::iter::once(&b' ')).enumerate() {
            match (numeric(b), start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    if bytes[s..i].iter().any(u8::is_ascii_digit) {
                        tokens.push(s..i);
                    }
                    start = None;
                }
                _ => {}
            }
        }
        if tokens.is_empty() {
            return self.edit_bytes(bytes);
        }
        let range = tokens[self.rng.below(tokens.len())].clone();
        let with = EXTREME_NUMBERS[self.rng.below(EXTREME_NUMBERS.len())];
        let description = format!("number at byte {} ({:?}) -> {with:?}", range.start, String::from_utf8_lossy(&bytes[range.clone()]));
        bytes.splice(range, with.bytes());
        description
    }

    /// Duplicates, removes or swaps whole lines.
    fn edit_lines(&mut self, bytes: &mut Vec<u8>) -> String {
        let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
        let (i, j) = (self.rng.below(lines.len()), self.rng.below(lines.len()));
        let description = match self.rng.below(3) {
            0 => {
                let copy = lines[i].clone();
                lines.insert(j, copy);
                format!("line {} duplicated before line {}", i + 1, j + 1)
            }
            1 => {
                lines.remove(i);
                format!("line {} removed", i + 1)
            }
            _ => {
                lines.swap(i, j);
                format!("lines {} and {} swapped", i + 1, j + 1)
            }
        };
        *bytes = lines.join(&b'\n');
        description
    }

    /// Replaces a 4-byte aligned little-endian word by an extreme.
    fn replace_word(&mut self, bytes: &mut [u8]) -> String {
        if bytes.len() < 4 {
            return self.edit_bytes_in_place(bytes);
        }
        let at = self.rng.below(bytes.len() / 4) * 4;
        let mut word = EXTREME_WORDS[self.rng.below(EXTREME_WORDS.len())];
        if self.rng.below(4) == 0 {
            word = bytes.len() as u32 + 1 + self.rng.below(64) as u32;
        }
        bytes[at..at + 4].copy_from_slice(&word.to_le_bytes());
        format!("word at byte {at} -> {word:#010x}")
    }

    /// Flips a bit, deletes, duplicates or inserts bytes, or truncates.
    fn edit_bytes(&mut self, bytes: &mut Vec<u8>) -> String {
        let len = bytes.len();
        let at = self.rng.below(len + 1);
        let run = 1 + self.rng.below(16);
        match self.rng.below(5) {
            0 if len > 0 => self.edit_bytes_in_place(bytes),
            1 if at < len => {
                let end = (at + run).min(len);
                bytes.drain(at..end);
                format!("bytes {at}..{end} deleted")
            }
            2 if at < len => {
                let end = (at + run).min(len);
                let copy = bytes[at..end].to_vec();
                bytes.splice(at..at, copy);
                format!("bytes {at}..{end} duplicated")
            }
            3 if at < len && self.rng.below(4) == 0 => {
                bytes.truncate(at);
                format!("truncated to {at} bytes")
            }
            _ => {
                let b = if self.rng.below(2) == 0 { INTERESTING_BYTES[self.rng.below(INTERESTING_BYTES.len())] } else { self.rng.next() as u8 };
                bytes.insert(at, b);
                format!("byte {b:#04x} inserted at {at}")
            }
        }
    }

    fn edit_bytes_in_place(&mut self, bytes: &mut [u8]) -> String {
        if bytes.is_empty() {
            return "nothing to flip in an empty input".into();
        }
        let at = self.rng.below(bytes.len());
        let bit = self.rng.below(8);
        bytes[at] ^= 1 << bit;
        format!("bit {bit} of byte {at} flipped")
    }
}

/// Cases per target: `FUZZ_CASES` if set, else [`DEFAULT_CASES`].
pub fn cases() -> usize {
    env_number("FUZZ_CASES").unwrap_or(DEFAULT_CASES as u64) as usize
}

/// The master seed: `FUZZ_SEED` if set, else [`DEFAULT_SEED`].
pub fn seed() -> u64 {
    env_number("FUZZ_SEED").unwrap_or(DEFAULT_SEED)
}

/// An environment variable as a number; a malformed value is a test setup
/// error and panics with its name.
fn env_number(name: &str) -> Option<u64> {
    let text = std::env::var(name).ok()?;
    Some(text.trim().parse().unwrap_or_else(|_| panic!("{name}={text:?} is not a non-negative integer")))
}

/// One case that panicked or hung.
#[derive(Debug, Clone)]
pub struct Failure {
    /// Case number (replay with `FUZZ_REPLAY`).
    pub case: usize,
    /// The panic message, or the hang.
    pub what: String,
    /// The mutations applied.
    pub mutations: Vec<String>,
    /// The mutant.
    pub input: Vec<u8>,
}

/// Runs `parse` on mutants of `seeds` (see the module doc) and
/// returns the failures, at most ten (the run stops at the tenth): case
/// numbers `case_numbers` under master seed `seed`, each allowed `timeout`
/// before it counts as a hang. Prints nothing;
/// [`fuzz`] is this plus the environment's settings and the report.
pub fn run_cases<F>(seeds: &[&[u8]], kind: Kind, seed: u64, case_numbers: impl Iterator<Item = usize>, timeout: Duration, parse: F) -> Vec<Failure>
where
    F: Fn(&[u8]) + Send + Sync + Clone + 'static,
{
    assert!(!seeds.is_empty(), "a fuzz target needs at least one seed input");
    let mut failures = Vec::new();
    for case in case_numbers {
        let (input, mutations) = Mutator::for_case(seed, case, kind).mutate(seeds);
        if let Some(what) = run_one(&input, timeout, parse.clone()) {
            failures.push(Failure { case, what, mutations, input });
            if failures.len() == 10 {
                break;
            }
        }
    }
    failures
}

/// Runs one case on its own thread: `None` if `parse` returned in time,
/// else what went wrong. A hung thread is left behind (it cannot be
/// killed); the test fails anyway.
fn run_one<F>(input: &[u8], timeout: Duration, parse: F) -> Option<String>
where
    F: Fn(&[u8]) + Send + 'static,
{
    let (sender, receiver) = mpsc::channel();
    let owned = input.to_vec();
    silence_case_panics();
    std::thread::spawn(move || {
        IN_CASE.with(|c| c.set(true));
        let outcome = catch_unwind(AssertUnwindSafe(|| parse(&owned)));
        let _ = sender.send(outcome.err().map(|payload| panic_message(payload.as_ref())));
    });
    match receiver.recv_timeout(timeout) {
        Ok(outcome) => outcome.map(|m| format!("panicked: {m}")),
        Err(mpsc::RecvTimeoutError::Timeout) => Some(format!("no answer within {:.1} s (hang?)", timeout.as_secs_f64())),
        Err(mpsc::RecvTimeoutError::Disconnected) => Some("the case's thread died without an answer".into()),
    }
}

fn panic_message(payload: &(dyn std::any::Any + Send)) -> String {
    payload.downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| payload.downcast_ref::<String>().cloned()).unwrap_or_else(|| "(non-text panic payload)".into())
}

/// The fuzz test of one parser: runs [`cases`]`()` cases (or only
/// `FUZZ_REPLAY`'s) under [`seed`]`()` and panics with a replayable report
/// if any case panicked or hung. The cases' own panic messages are
/// silenced, so the report is the only output.
pub fn fuzz<F>(target: &str, seeds: &[&[u8]], kind: Kind, parse: F)
where
    F: Fn(&[u8]) + Send + Sync + Clone + 'static,
{
    let seed = seed();
    let numbers: Box<dyn Iterator<Item = usize>> = match env_number("FUZZ_REPLAY") {
        Some(case) => Box::new(std::iter::once(case as usize)),
        None => Box::new(0..cases()),
    };
    let trace = std::env::var_os("FUZZ_TRACE").is_some();
    let numbers = numbers.inspect(move |case| {
        if trace {
            eprintln!("fuzz target {target}: case {case}");
        }
    });
    let failures = run_cases(seeds, kind, seed, numbers, CASE_TIMEOUT, parse);
    if failures.is_empty() {
        return;
    }
    let mut report = format!("fuzz target {target}: {} failing case(s) under FUZZ_SEED={seed}\n", failures.len());
    for f in &failures {
        report += &format!(
            "  case {} (replay: FUZZ_SEED={seed} FUZZ_REPLAY={} cargo test --release -- fuzz_): {}\n    mutations: {}\n    input: {}\n",
            f.case,
            f.case,
            f.what,
            f.mutations.join("; "),
            show(&f.input, kind)
        );
    }
    panic!("{report}");
}

thread_local! {
    /// Whether this thread runs a fuzz case, whose panics the harness reports.
    static IN_CASE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Installs, once per process, a panic hook that is silent on fuzz case
/// threads and defers to the previous hook everywhere else, so other tests'
/// panic messages still show.
fn silence_case_panics() {
    static INSTALLED: std::sync::Once = std::sync::Once::new();
    INSTALLED.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !IN_CASE.with(std::cell::Cell::get) {
                previous(info);
            }
        }));
    });
}

/// The mutant as text (lossy, escaped) or hex, cut at 2,000 characters.
fn show(input: &[u8], kind: Kind) -> String {
    let text = match kind {
        Kind::Text => format!("{:?}", String::from_utf8_lossy(input)),
        Kind::Binary => input.iter().map(|b| format!("{b:02x}")).collect(),
    };
    match text.char_indices().nth(2000) {
        Some((cut, _)) => format!("{}... ({} bytes)", &text[..cut], input.len()),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn a_case_is_the_same_mutant_every_time_and_cases_differ() {
        let a = Mutator::for_case(7, 42, Kind::Text).mutate(&[OBJ]);
        let b = Mutator::for_case(7, 42, Kind::Text).mutate(&[OBJ]);
        assert_eq!(a.0, b.0);
        assert_eq!(a.1, b.1);
        let distinct: std::collections::HashSet<Vec<u8>> = (0..100).map(|k| Mutator::for_case(7, k, Kind::Text).mutate(&[OBJ]).0).collect();
        assert!(distinct.len() > 80, "only {} distinct mutants of 100", distinct.len());
    }

    #[test]
    fn text_mutations_include_extreme_numbers_and_line_edits() {
        let all: Vec<String> = (0..400).flat_map(|k| Mutator::for_case(1, k, Kind::Text).mutate(&[OBJ]).1).collect();
        for needle in ["-> \"NaN\"", "-> \"1e308\"", "removed", "swapped", "duplicated before", "inserted", "flipped"] {
            assert!(all.iter().any(|m| m.contains(needle)), "no mutation {needle:?} in 400 cases");
        }
    }

    #[test]
    fn binary_mutations_replace_words() {
        let input = [0u8; 64];
        let all: Vec<String> = (0..200).flat_map(|k| Mutator::for_case(1, k, Kind::Binary).mutate(&[&input]).1).collect();
        assert!(all.iter().any(|m| m.contains("word at byte") && m.contains("0x7fc00000")), "no NaN word in 200 cases");
    }

    #[test]
    fn panics_and_hangs_are_caught_and_named_by_case() {
        let panicking = run_cases(&[OBJ], Kind::Text, 3, 0..50, CASE_TIMEOUT, |bytes| {
            assert!(!bytes.contains(&b'\n') || bytes.len() < 30, "too long");
        });
        assert!(!panicking.is_empty());
        assert!(panicking[0].what.contains("panicked: too long"), "{}", panicking[0].what);
        let replayed = Mutator::for_case(3, panicking[0].case, Kind::Text).mutate(&[OBJ]).0;
        assert_eq!(replayed, panicking[0].input, "the reported case replays to the same input");
        let hanging = run_cases(&[OBJ], Kind::Text, 3, 0..1, Duration::from_millis(50), |_| std::thread::sleep(Duration::from_secs(2)));
        assert_eq!(hanging.len(), 1);
        assert!(hanging[0].what.contains("hang"), "{}", hanging[0].what);
    }

    #[test]
    fn a_parser_that_never_fails_passes() {
        fuzz("lossy-utf8", &[OBJ], Kind::Text, |bytes| {
            let _ = String::from_utf8_lossy(bytes);
        });
    }
}
