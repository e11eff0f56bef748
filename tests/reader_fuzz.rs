//! Readers that never panic (issue 17, item 7): every reader of the project is fed mutated copies of
//! valid seed files and must answer `Ok` or a one-line error that names the file (and the line where
//! the reader knows it), never a panic.
//!
//! The mutations are deterministic (a seeded SplitMix64, so a failure names the case that
//! reproduces it): byte changes, truncation, line deletion, duplication and swaps, numbers replaced
//! by NaN, infinities, huge, negative or malformed values, tokens deleted, keywords swapped between
//! lines or with the reader's other keywords, and garbage lines, one to four per input.
//!
//! To fuzz a new reader, add one line to [`targets`] (each reader runs on its own thread):
//! `Target::new("ies", "lamp.ies", &[SEED], &["TILT=", ...], |text, path| ies::parse(text, path).map(drop).map_err(|e| e.to_string()))`
//! (name, the file name its errors must name, seed texts, keywords for swaps, the call).
//!
//! `cargo fuzz` (libFuzzer) needs a nightly toolchain, which this project's pinned stable toolchain
//! cannot fetch; this test is the stable, CI-run substitute.

use radiosity_core::instancing;
use radiosity_core::oracle::runtime::parse_graph;
use radiosity_core::points::parse_points;
use radiosity_core::scene::mgf::{MgfOptions, load_str as load_mgf};
use radiosity_core::scene::obj::load_str as load_obj;
use std::path::Path;
use std::time::{Duration, Instant};

/// Mutated inputs per seed file (every target has 1 or 2 seeds); `RADIOSITY_FUZZ_CASES=N` runs N
/// instead, `RADIOSITY_FUZZ_SEED=N` starts the generator elsewhere, `RADIOSITY_FUZZ_ONLY=NAME`
/// runs one reader and `RADIOSITY_FUZZ_TRACE=1` prints each case and its input before running it (to find an
/// input that crashes the process), for longer hunts.
const CASES_PER_SEED: u64 = 2500;
/// An input that takes longer than this is a failure (a reader that hangs is as bad as a panic).
const SLOW_INPUT: Duration = Duration::from_secs(2);

const CORNELL_OBJ: &str = include_str!("../radiosity-core/data/cornell_box_measured.obj");
const CORNELL_MTL: &str = include_str!("../radiosity-core/data/cornell_box_measured.mtl");
const IES_DOWNLIGHT: &str = include_str!("../radiosity-core/data/luminaires/downlight_asymmetric.ies");
const IES_LINEAR: &str = include_str!("../radiosity-core/data/luminaires/linear_example.ies");
const LDT_DOWNLIGHT: &str = include_str!("../radiosity-core/data/luminaires/downlight_asymmetric.ldt");

/// A lighting scene file: units, a luminaire (one of the shipped files) and a grid.
const LIT_TOML: &str = r#"# fuzz seed: lighting
units = "photometric"
[[material]]
name = "grey"
reflectance = 0.5
[[box]]
min = [0, 0, 0]
max = [4, 4, 3]
material = "grey"
inward = true
[[luminaire]]
ies = "downlight_asymmetric.ies"
position = [2.0, 2.0, 2.9]
aim = [0.0, 0.0, -1.0]
rotate = 15.0
multiplier = 1.5
[[grid]]
name = "work"
origin = [0.5, 0.5, 0.8]
u = [3.0, 0.0, 0.0]
v = [0.0, 3.0, 0.0]
spacing = 0.25
normal = [0.0, 0.0, 1.0]
"#;

const MGF_ROOM: &str = "# fuzz seed: a room with a lamp, colours and transforms
c red =
 cxy .64 .33
c warm =
 cct 3000
m white =
 c
 rd .5
 sides 1
m redwall =
 c red
 rd .4
 td .1
m lamp =
 c warm
 ed 100
v a =
 p 0 0 0
 n 0 0 1
v b =
 p 4 0 0
v c =
 p 4 4 0
v d =
 p 0 4 0
o room
m white
f a b c d
xf -t 0 0 3 -rz 30 -s 1.5
m redwall
f d c b a
xf
o
m lamp
xf -t 1 1 2.9
f a b c
xf
";

const MGF_PRIMITIVES: &str = "# fuzz seed: primitives and an array
m grey =
 c
 rd .3
m lamp =
 c
 ed 10
v o =
 p 0 0 0
 n 0 0 1
v t =
 p 0 0 1
 n 0 0 1
v p1 =
 p 0 0 0
v p2 =
 p 1 0 0
v p3 =
 p 0 1 0
m grey
sph o .5
cyl o .2 t
cone o .3 t .1
ring o .1 .4
torus o .1 .3
prism p1 p2 p3 .5
xf -a 3 -t 2 0 0
m lamp
ring t 0 .2
xf
fh p1 p2 p3 - p1 p2 p3
";

const INSTANCED: &str = r#"# fuzz seed: nested instances
name = "nested"
[[material]]
name = "white"
reflectance = 0.5
[[material]]
name = "leaf"
reflectance = [0.2, 0.4, 0.1]
transmittance = 0.2
[[material]]
name = "light"
reflectance = 0.0
emission = 10.0
two_sided = false

[[polygon]]
material = "white"
vertices = [[0, 0, 0], [4, 0, 0], [4, 4, 0], [0, 4, 0]]

[[box]]
min = [0, 0, 0]
max = [4, 4, 4]
material = "white"
inward = true

[[instance]]
of = "branch"
translate = [1, 1, 0]

[[instance]]
of = "branch"
translate = [3, 1, 0]
rotate = [0, 0, 90]
scale = 0.5

[[prototype]]
name = "leaf"
[[prototype.polygon]]
material = "leaf"
vertices = [[0, 0, 0], [0.1, 0, 0], [0.1, 0.1, 0]]

[[prototype]]
name = "branch"
[[prototype.box]]
min = [0, 0, 0]
max = [0.1, 0.1, 1]
material = "white"
[[prototype.instance]]
of = "leaf"
translate = [0, 0, 1]
[[prototype.instance]]
of = "leaf"
matrix = [1, 0, 0, 0,  0, 1, 0, 0,  0, 0, 1, 0.5]
"#;

const GRAPH: &str = r#"# fuzz seed: a small oracle graph
name = "fuzz"
start = "near"
[[node]]
name = "near"
tool = "ClusterTooNear"
arms = [{ on = "Yes", to = "size" }, { on = "No", to = "link" }]
[[node]]
name = "size"
tool = "CanSubdivide"
args = [0.0]
arms = [
  { on = "Neither", to = "link" },
  { on = "Emitter | Receiver | Both", to = "facing" },
]
[[node]]
name = "facing"
tool = "Facing"
arms = [{ on = "Yes", to = "subdivide_both" }, { on = "No", to = "stop" }]
[[param]]
name = "eps"
default = 0.5
"#;

const POINTS_HEADER: &str = "# fuzz seed: calculation points with a header\n\
name,x,y,z,nx,ny,nz\n\
floor centre,0.5,0.5,0,0,0,1\n\
\"A, left\",0.1,0.2,0,0,0,1\n\
,0.9,0.9,1,0,0,-1\n\
wall,0,0.5,0.5,1,0,0\n";

const POINTS_PLAIN: &str = "0.5,0.5,0,0,0,1\n0.25,0.75,0,0,0,2\n\n# comment\n1,1,1,-1,-1,-1\n";

/// One reader under test.
struct Target {
    name: &'static str,
    /// The file name passed to the reader; every error must name it.
    file: &'static str,
    seeds: &'static [&'static str],
    /// Words swapped in as a line's first word, besides the other lines' first words.
    keywords: &'static [&'static str],
    read: fn(&str, &Path) -> Result<(), String>,
}

impl Target {
    const fn new(
        name: &'static str,
        file: &'static str,
        seeds: &'static [&'static str],
        keywords: &'static [&'static str],
        read: fn(&str, &Path) -> Result<(), String>,
    ) -> Target {
        Target { name, file, seeds, keywords, read }
    }
}

/// Every reader, one line each.
fn targets() -> Vec<Target> {
    const OBJ_KEYS: &[&str] = &["v", "vt", "vn", "f", "l", "p", "o", "g", "s", "usemtl", "mtllib", "#"];
    const MTL_KEYS: &[&str] =
        &["newmtl", "Ka", "Kd", "Ks", "Ke", "Kt", "Ns", "Ni", "d", "Tr", "illum", "map_Kd", "map_Ka", "bump", "map_d", "two_sided"];
    const MGF_KEYS: &[&str] = &[
        "v", "p", "n", "f", "fh", "sph", "cyl", "cone", "ring", "torus", "prism", "c", "cxy", "cspec", "cct", "cmix", "m", "rd", "td",
        "ed", "rs", "ts", "sides", "ir", "o", "xf", "i", "ies",
    ];
    const TOML_KEYS: &[&str] =
        &["[[material]]", "[[prototype]]", "[[instance]]", "[[node]]", "name =", "of =", "obj =", "uses =", "start ="];
    const LIT_KEYS: &[&str] = &["units =", "[[luminaire]]", "[[grid]]", "ies =", "ldt =", "aim =", "spacing =", "normal =", "u ="];
    const IES_KEYS: &[&str] = &["TILT=NONE", "TILT=INCLUDE", "TILT=lamp.tlt", "IESNA:LM-63-2002", "IESNA:LM-63-1995", "[TEST]", "0", "-1"];
    const CSV_KEYS: &[&str] = &["name,x,y,z,nx,ny,nz", "x,y,z,nx,ny,nz", "\"", ",", "#"];
    vec![
        Target::new("obj", "scene.obj", &[CORNELL_OBJ], OBJ_KEYS, |text, path| {
            load_obj(text, path, "scene", |_| Ok(CORNELL_MTL.to_owned())).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("mtl", "scene.mtl", &[CORNELL_MTL], MTL_KEYS, |text, _| {
            let mtl = text.to_owned();
            let obj = CORNELL_OBJ.replace("mtllib cornell_box_measured.mtl", "mtllib scene.mtl");
            load_obj(&obj, Path::new("scene.obj"), "scene", move |_| Ok(mtl.clone())).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("mgf", "scene.mgf", &[MGF_ROOM, MGF_PRIMITIVES], MGF_KEYS, |text, path| {
            load_mgf(text, path, &MgfOptions::default()).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("instanced", "scene.toml", &[INSTANCED], TOML_KEYS, |text, path| {
            instancing::parse(text, path, Path::new("no-such-dir")).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("lighting", "room.toml", &[LIT_TOML], LIT_KEYS, |text, path| {
            let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("radiosity-core/data/luminaires");
            instancing::parse_with_lighting(text, path, &dir).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("ies", "lamp.ies", &[IES_DOWNLIGHT, IES_LINEAR], IES_KEYS, |text, path| {
            radiosity::photometry::parse_ies(text, &path.display().to_string()).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("ldt", "lamp.ldt", &[LDT_DOWNLIGHT], &["0", "1", "2", "3", "4", "-1"], |text, path| {
            radiosity::photometry::parse_ldt(text, &path.display().to_string()).map(drop).map_err(|e| e.to_string())
        }),
        Target::new("graph", "graph.toml", &[GRAPH], TOML_KEYS, |text, path| parse_graph(text, path).map(drop).map_err(|e| e.to_string())),
        Target::new("points", "points.csv", &[POINTS_HEADER, POINTS_PLAIN], CSV_KEYS, |text, path| {
            parse_points(path, text).map(drop).map_err(|e| e.to_string())
        }),
    ]
}

/// SplitMix64: small, seeded, good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `0..n` (`n > 0`).
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
        xs[self.below(xs.len())]
    }
}

/// Replacements for a number token.
const BAD_NUMBERS: &[&str] = &[
    "NaN",
    "nan",
    "inf",
    "-inf",
    "infinity",
    "1e308",
    "1e309",
    "-1e309",
    "-1",
    "-0",
    "0",
    "1e-320",
    "99999999999999999999",
    "4294967296",
    "-2147483649",
    "18446744073709551616",
    "",
    "-",
    "+",
    ".",
    "1e",
    "0x10",
    "1,5",
    "1.2.3",
    "½",
];

/// Garbage lines.
const GARBAGE: &[&str] = &["\u{0}", "\u{feff}", "[[", "]]", "=", "\"", "'''", "{", "é ü ☃", "\t \t", "\\", "f", "-a 1000", "a = b = c"];

fn is_number(w: &str) -> bool {
    !w.is_empty() && w.trim_matches(|c: char| c == ',' || c == ']' || c == '[').parse::<f64>().is_ok()
}

/// Applies one random mutation.
fn mutate_once(rng: &mut Rng, text: &str, keywords: &[&str]) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    if lines.is_empty() {
        lines.push(String::new());
    }
    let n = lines.len();
    match rng.below(10) {
        0 => {
            // Byte changes, then back to text (readers take text; invalid UTF-8 is the file read's error).
            let mut bytes = text.as_bytes().to_vec();
            if bytes.is_empty() {
                bytes.push(b'x');
            }
            for _ in 0..1 + rng.below(4) {
                let i = rng.below(bytes.len());
                bytes[i] = match rng.below(3) {
                    0 => bytes[i] ^ (1 << rng.below(8)),
                    1 => b" \n\t,=\"[]{}#-.0123456789eE"[rng.below(25)],
                    _ => rng.next() as u8,
                };
            }
            return String::from_utf8_lossy(&bytes).into_owned();
        }
        1 => {
            let cut = rng.below(text.len() + 1);
            let cut = (0..=cut).rev().find(|&i| text.is_char_boundary(i)).unwrap_or(0);
            return text[..cut].to_owned();
        }
        2 => {
            let _ = lines.remove(rng.below(n));
        }
        3 => {
            let i = rng.below(n);
            let line = lines[i].clone();
            lines.insert(rng.below(n + 1), line);
        }
        4 => {
            let (i, j) = (rng.below(n), rng.below(n));
            lines.swap(i, j);
        }
        5 | 6 => {
            // Replace a number token (or any token when the line has no number).
            let i = rng.below(n);
            let mut words: Vec<String> = lines[i].split(' ').map(str::to_owned).collect();
            let numbers: Vec<usize> = (0..words.len()).filter(|&k| is_number(&words[k])).collect();
            let k = if numbers.is_empty() { rng.below(words.len()) } else { numbers[rng.below(numbers.len())] };
            let bad = rng.pick(BAD_NUMBERS);
            // Keep TOML/CSV punctuation around the number.
            let w = &words[k];
            let (pre, post) = (w.len() - w.trim_start_matches(['[', '"']).len(), w.len() - w.trim_end_matches([',', ']', '"', '}']).len());
            words[k] = format!("{}{bad}{}", &w[..pre], &w[w.len() - post..]);
            lines[i] = words.join(" ");
        }
        7 => {
            // Delete a token (a missing number or name).
            let i = rng.below(n);
            let mut words: Vec<&str> = lines[i].split_whitespace().collect();
            if !words.is_empty() {
                let _ = words.remove(rng.below(words.len()));
            }
            lines[i] = words.join(" ");
        }
        8 => {
            // Keyword swap: a line's first word becomes another line's or one of the reader's.
            let i = rng.below(n);
            let other = lines[rng.below(n)].split_whitespace().next().unwrap_or("").to_owned();
            let new = if keywords.is_empty() || rng.below(2) == 0 { other } else { rng.pick(keywords).to_owned() };
            let rest: Vec<&str> = lines[i].split_whitespace().skip(1).collect();
            lines[i] = format!("{new} {}", rest.join(" "));
        }
        _ => lines.insert(rng.below(n + 1), rng.pick(GARBAGE).to_owned()),
    }
    let mut out = lines.join("\n");
    if text.ends_with('\n') {
        out.push('\n');
    }
    out
}

/// One to four stacked mutations.
fn mutate(rng: &mut Rng, seed: &str, keywords: &[&str]) -> String {
    let mut text = seed.to_owned();
    for _ in 0..1 + rng.below(4) {
        text = mutate_once(rng, &text, keywords);
    }
    text
}

/// Tallies of one target's run.
#[derive(Default)]
struct Tally {
    inputs: u64,
    accepted: u64,
    rejected: u64,
    with_line: u64,
    failures: Vec<String>,
}

thread_local! {
    static LAST_PANIC: std::cell::RefCell<String> = const { std::cell::RefCell::new(String::new()) };
    static QUIET: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// While [`QUIET`] is set on the panicking thread, records the panic message for the failure
/// report instead of printing it; otherwise (the test's own assertions) calls the previous hook.
fn quiet_panics() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(std::cell::Cell::get) {
                return previous(info);
            }
            let at = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
            let msg = info
                .payload()
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| info.payload().downcast_ref::<String>().cloned())
                .unwrap_or_default();
            LAST_PANIC.with(|p| *p.borrow_mut() = format!("{msg}{at}"));
        }));
    });
}

/// Checks one rejection: one line (a graph file lists every problem, one per line, each naming the
/// file) that starts with the file name and gives a reason.
fn check_message(file: &str, msg: &str) -> Result<bool, String> {
    let mut with_line = true;
    for line in msg.lines() {
        let Some(rest) = line.strip_prefix(file) else { return Err(format!("does not start with `{file}`")) };
        let Some(rest) = rest.strip_prefix(':') else { return Err("no `:` after the file name".into()) };
        let (num, reason) = rest.split_once(':').filter(|(n, _)| n.parse::<usize>().is_ok()).unwrap_or(("", rest));
        with_line &= !num.is_empty();
        if reason.trim().is_empty() {
            return Err("no reason".into());
        }
    }
    if msg.is_empty() || msg.ends_with('\n') {
        return Err("empty or ends with a newline".into());
    }
    Ok(with_line)
}

fn cases_per_seed() -> u64 {
    std::env::var("RADIOSITY_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(CASES_PER_SEED)
}

fn base_seed() -> u64 {
    std::env::var("RADIOSITY_FUZZ_SEED").ok().and_then(|v| v.parse().ok()).unwrap_or(0x5eed_0017)
}

/// Runs the reader on `input`; `Err(())` when it panicked (the message is in [`LAST_PANIC`]).
fn guarded(t: &Target, input: &str) -> Result<Result<(), String>, ()> {
    QUIET.with(|q| q.set(true));
    let result = std::panic::catch_unwind(|| (t.read)(input, Path::new(t.file)));
    QUIET.with(|q| q.set(false));
    result.map_err(drop)
}

fn run_target(t: &Target, base_seed: u64) -> Tally {
    quiet_panics();
    let mut tally = Tally::default();
    let trace = std::env::var_os("RADIOSITY_FUZZ_TRACE").is_some();
    for (s, seed) in t.seeds.iter().enumerate() {
        // The seed itself must load: the mutations start from valid input.
        match guarded(t, seed) {
            Ok(Ok(())) => {}
            Ok(Err(e)) => tally.failures.push(format!("{} seed {s} does not load: {e}", t.name)),
            Err(()) => tally.failures.push(format!("{} seed {s} panicked: {}", t.name, LAST_PANIC.with(|p| p.borrow().clone()))),
        }
        for case in 0..cases_per_seed() {
            // The base seed's multiple by an odd constant spreads it over the high bits, so two base
            // seeds give disjoint case sequences.
            let case_seed = base_seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ ((s as u64) << 40) ^ case;
            let mut rng = Rng(case_seed);
            let input = mutate(&mut rng, seed, t.keywords);
            tally.inputs += 1;
            let t0 = Instant::now();
            if trace {
                eprintln!("{} seed {s} case {case}\n{input}", t.name);
            }
            let result = guarded(t, &input);
            let elapsed = t0.elapsed();
            let describe =
                |what: String| format!("{} seed {s} case {case} (rng {case_seed:#x}): {what}\n--- input ---\n{input}\n---", t.name);
            if elapsed > SLOW_INPUT {
                tally.failures.push(describe(format!("took {elapsed:?}")));
            }
            match result {
                Err(_) => tally.failures.push(describe(format!("panicked: {}", LAST_PANIC.with(|p| p.borrow().clone())))),
                Ok(Ok(())) => tally.accepted += 1,
                Ok(Err(msg)) => {
                    tally.rejected += 1;
                    match check_message(t.file, &msg) {
                        Ok(line) => tally.with_line += u64::from(line),
                        Err(why) => tally.failures.push(describe(format!("bad message ({why}): {msg:?}"))),
                    }
                }
            }
        }
    }
    tally
}

/// Every reader of [`targets`], each on its own thread.
#[test]
fn readers_never_panic_on_mutated_input() {
    let t0 = Instant::now();
    let mut targets = targets();
    if let Ok(only) = std::env::var("RADIOSITY_FUZZ_ONLY") {
        targets.retain(|t| t.name == only);
    }
    let tallies: Vec<(Tally, Duration)> = std::thread::scope(|scope| {
        let handles: Vec<_> = targets
            .iter()
            .map(|t| {
                scope.spawn(move || {
                    let t0 = Instant::now();
                    (run_target(t, base_seed()), t0.elapsed())
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().expect("fuzz thread")).collect()
    });
    let mut failures = Vec::new();
    let mut total = 0;
    for (t, (tally, elapsed)) in targets.iter().zip(&tallies) {
        eprintln!(
            "{}: {} inputs in {elapsed:.2?}: {} accepted, {} rejected ({} naming a line), {} failures",
            t.name,
            tally.inputs,
            tally.accepted,
            tally.rejected,
            tally.with_line,
            tally.failures.len()
        );
        total += tally.inputs;
        failures.extend(tally.failures.iter().take(3).cloned());
        assert!(tally.rejected > tally.inputs / 10, "{}: mutations too mild: only {} of {} rejected", t.name, tally.rejected, tally.inputs);
    }
    eprintln!("{total} inputs in {:.2?}", t0.elapsed());
    assert!(failures.is_empty(), "failures (first 3 per reader):\n{}", failures.join("\n"));
}

/// The known `tobj` 4.0.5 panic (issue 17): `Ke` with fewer than three numbers.
#[test]
fn short_ke_line_is_an_error_naming_the_mtl_line() {
    let mtl: String = CORNELL_MTL.lines().map(|l| if l.starts_with("Ke") { "Ke 17 12\n".to_owned() } else { format!("{l}\n") }).collect();
    let obj = CORNELL_OBJ.replace("mtllib cornell_box_measured.mtl", "mtllib scene.mtl");
    let e = load_obj(&obj, Path::new("dir/scene.obj"), "scene", |_| Ok(mtl.clone())).expect_err("short Ke").to_string();
    let line = mtl.lines().position(|l| l.starts_with("Ke 17 12")).expect("mutated line") + 1;
    assert_eq!(line, 18);
    assert_eq!(e, format!("dir/scene.mtl:{line}: `Ke` needs 3 numbers, found 2"));
}

/// The harness itself: a reader that panics, one that hangs on nothing, and one whose message does
/// not name the file are all failures.
#[test]
fn harness_reports_panics_and_bad_messages() {
    let panicking = Target::new("panics", "x.txt", &["1 2 3\n"], &[], |text, _| if text.len() % 2 == 0 { panic!("boom") } else { Ok(()) });
    let tally = run_target(&panicking, 1);
    assert!(tally.failures.iter().any(|f| f.contains("panicked: boom")), "{:?}", tally.failures.first());
    let unnamed = Target::new("unnamed", "x.txt", &["1 2 3\n"], &[], |_, _| Err("something is wrong".to_owned()));
    let tally = run_target(&unnamed, 1);
    assert_eq!(tally.failures.len() as u64, tally.inputs + 1, "every input and the seed fail");
    assert!(tally.failures[1].contains("does not start with `x.txt`"), "{}", tally.failures[1]);
    assert_eq!(check_message("x.txt", "x.txt:3: bad"), Ok(true));
    assert_eq!(check_message("x.txt", "x.txt: bad"), Ok(false));
    assert!(check_message("x.txt", "x.txt:3: bad\nmore").is_err());
    assert!(check_message("x.txt", "x.txt:3: ").is_err());
}
