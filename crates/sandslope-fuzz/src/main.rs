//! `sandslope-fuzz`: mutation fuzzing of every sandslope reader and every command that reads a
//! file (issue 21). Run it through `scripts/fuzz.sh N [TARGET...]`.
//!
//! For each target, N inputs are made by mutating its seed files (`mutate.rs`), each input `i`
//! from the random seed `(--seed, i)`, so any failure is reproduced by its index alone. Readers
//! run in process, in child processes of chunks of inputs (an abort kills only its chunk, which
//! is then re-run one input at a time to find it); commands run as the `sandslope` binary, one
//! process per input. Every child runs under an address-space limit (`--mem-limit-mib`), so an
//! allocation bomb is an abort here, not a machine brought down; a run that takes longer than
//! `--timeout` seconds is a hang. Reported per target: runs, exit codes, panics, aborts, hangs,
//! peak resident memory (the largest of any child) and time. Failing inputs are kept in
//! `--out` (default `fuzz-out/`) with the command that reproduces them. Exit code 1 when any
//! target had a panic, abort, hang or a peak above `--max-peak-mib`.

mod mutate;
mod serve;
mod targets;

use std::collections::BTreeMap;
use std::io::Write;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{anyhow, bail, Context, Result};
use rand::rngs::StdRng;
use rand::{RngExt, SeedableRng};

use targets::{Run, Target, TARGETS};

/// Inputs per reader child process.
const CHUNK: u64 = 500;

#[derive(Clone)]
struct Options {
    runs: u64,
    seed: u64,
    timeout: Duration,
    mem_limit_mib: u64,
    max_peak_mib: u64,
    out: PathBuf,
    bin: PathBuf,
    repo: PathBuf,
    targets: Vec<&'static Target>,
}

fn usage() -> String {
    let names: Vec<&str> = TARGETS.iter().map(|t| t.name).collect();
    format!(
        "usage: sandslope-fuzz [--runs N] [--seed S] [--timeout SECONDS] [--mem-limit-mib M] \
         [--max-peak-mib M] [--out DIR] [--bin PATH/TO/sandslope] [--repo DIR] [TARGET...]\n\
         targets: {}\n\
         also: sandslope-fuzz --emit TARGET --from I --to J --dir DIR (write inputs I..J for other fuzzers)",
        names.join(" ")
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let code = match args.first().map(String::as_str) {
        Some("--child") => child(&args[1..]).map(|()| 0),
        Some("--emit") => emit(&args[1..]).map(|()| 0),
        Some("-h" | "--help") => {
            println!("{}", usage());
            Ok(0)
        }
        _ => parse(&args).and_then(|o| parent(&o)),
    };
    match code {
        Ok(c) => std::process::exit(c),
        Err(e) => {
            eprintln!("sandslope-fuzz: {e:#}");
            std::process::exit(2);
        }
    }
}

fn value<'a>(args: &'a [String], i: &mut usize, flag: &str) -> Result<&'a str> {
    *i += 1;
    args.get(*i).map(String::as_str).ok_or_else(|| anyhow!("{flag} needs a value\n{}", usage()))
}

fn number<T: std::str::FromStr>(text: &str, flag: &str) -> Result<T> {
    text.parse().map_err(|_| anyhow!("{flag} = {text} is not a whole number\n{}", usage()))
}

fn parse(args: &[String]) -> Result<Options> {
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let exe = std::env::current_exe()?;
    let mut o = Options {
        runs: 1000,
        seed: 1,
        timeout: Duration::from_secs(10),
        mem_limit_mib: 4096,
        max_peak_mib: 1024,
        out: PathBuf::from("fuzz-out"),
        bin: exe.with_file_name("sandslope"),
        repo,
        targets: Vec::new(),
    };
    let mut i = 0;
    while i < args.len() {
        let a = args[i].as_str();
        match a {
            "--runs" => o.runs = number(value(args, &mut i, a)?, a)?,
            "--seed" => o.seed = number(value(args, &mut i, a)?, a)?,
            "--timeout" => o.timeout = Duration::from_secs(number(value(args, &mut i, a)?, a)?),
            "--mem-limit-mib" => o.mem_limit_mib = number(value(args, &mut i, a)?, a)?,
            "--max-peak-mib" => o.max_peak_mib = number(value(args, &mut i, a)?, a)?,
            "--out" => o.out = PathBuf::from(value(args, &mut i, a)?),
            "--bin" => o.bin = PathBuf::from(value(args, &mut i, a)?),
            "--repo" => o.repo = PathBuf::from(value(args, &mut i, a)?),
            name if !name.starts_with('-') => {
                o.targets.push(targets::find(name).ok_or_else(|| anyhow!("no target `{name}`\n{}", usage()))?)
            }
            other => bail!("unknown option {other}\n{}", usage()),
        }
        i += 1;
    }
    if o.targets.is_empty() {
        o.targets = TARGETS.iter().collect();
    }
    if o.targets.iter().any(|t| matches!(t.run, Run::Command(_) | Run::Serve(_))) && !o.bin.is_file() {
        bail!("{}: no sandslope binary (build it, or give --bin)", o.bin.display());
    }
    Ok(o)
}

/// Input `i` of a target with these seed files: a seed chosen and mutated by the generator seeded with `(seed, i)`.
fn input(seeds: &[Vec<u8>], seed: u64, i: u64) -> Vec<u8> {
    let mut rng = StdRng::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i);
    let base = &seeds[rng.random_range(0..seeds.len())];
    mutate::mutate(base, &mut rng)
}

fn read_seeds(repo: &Path, target: &Target) -> Result<Vec<Vec<u8>>> {
    target
        .seeds
        .iter()
        .map(|s| {
            let p = targets::repo_path(repo, s);
            std::fs::read(&p).with_context(|| format!("seed {}", p.display()))
        })
        .collect()
}

/// A fresh working folder holding the target's companion files.
fn work_dir(repo: &Path, target: &Target, dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)?;
    for c in target.companions {
        let files: Vec<PathBuf> = match c.strip_suffix("/*.csv") {
            Some(folder) => std::fs::read_dir(targets::repo_path(repo, folder))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|x| x == "csv"))
                .collect(),
            None => vec![targets::repo_path(repo, c)],
        };
        for src in files {
            let name = src.file_name().ok_or_else(|| anyhow!("companion {c} has no file name"))?;
            std::fs::copy(&src, dir.join(name)).with_context(|| format!("companion {}", src.display()))?;
        }
    }
    Ok(())
}

/// Sets the address-space limit of the process about to run (in `pre_exec`).
fn limit_memory(cmd: &mut Command, mib: u64) {
    let bytes = mib.saturating_mul(1 << 20);
    // SAFETY: setrlimit is async-signal-safe, and nothing else runs between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            let lim = libc::rlimit { rlim_cur: bytes as libc::rlim_t, rlim_max: bytes as libc::rlim_t };
            if libc::setrlimit(libc::RLIMIT_AS, &lim) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
}

/// How a child ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ending {
    Exit(i32),
    Signal(i32),
    Timeout,
}

/// Waits for `pid` up to `timeout` (killing it then), with its peak resident memory in KiB.
fn wait_with_rusage(pid: u32, timeout: Duration) -> Result<(Ending, u64)> {
    let start = Instant::now();
    let pid = pid as libc::pid_t;
    let mut timed_out = false;
    loop {
        let mut status = 0;
        // SAFETY: plain FFI with valid pointers to locals.
        let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
        let flags = if timed_out { 0 } else { libc::WNOHANG };
        let r = unsafe { libc::wait4(pid, &mut status, flags, &mut usage) };
        if r == pid {
            let peak = usage.ru_maxrss.max(0) as u64;
            let ending = if timed_out {
                Ending::Timeout
            } else if libc::WIFEXITED(status) {
                Ending::Exit(libc::WEXITSTATUS(status))
            } else {
                Ending::Signal(libc::WTERMSIG(status))
            };
            return Ok((ending, peak));
        }
        if r < 0 {
            return Err(std::io::Error::last_os_error().into());
        }
        if start.elapsed() > timeout && !timed_out {
            unsafe { libc::kill(pid, libc::SIGKILL) };
            timed_out = true;
            continue;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// What one target's runs gave.
#[derive(Debug, Default)]
struct Tally {
    runs: u64,
    exits: BTreeMap<i32, u64>,
    panics: Vec<String>,
    aborts: Vec<String>,
    hangs: Vec<String>,
    /// Runs whose peak resident memory exceeded `--max-peak-mib`.
    memory: Vec<String>,
    peak_kib: u64,
    seconds: f64,
}

impl Tally {
    fn failed(&self, max_peak_mib: u64) -> bool {
        !self.panics.is_empty()
            || !self.aborts.is_empty()
            || !self.hangs.is_empty()
            || self.peak_kib > max_peak_mib * 1024
    }
}

fn parent(o: &Options) -> Result<i32> {
    println!(
        "sandslope-fuzz: {} inputs per target, seed {}, timeout {} s, address space {} MiB",
        o.runs,
        o.seed,
        o.timeout.as_secs(),
        o.mem_limit_mib
    );
    println!(
        "{:<17} {:>8} {:>7} {:>7} {:>6} {:>7} {:>6} {:>9} {:>8}  exit codes",
        "target", "runs", "panics", "aborts", "hangs", "memory", "ok", "peak MiB", "seconds"
    );
    let mut any_failed = false;
    for target in &o.targets {
        let start = Instant::now();
        let mut notes = Vec::new();
        let mut tally = match target.run {
            Run::Reader(_) => fuzz_reader(o, target)?,
            Run::Command(args) => fuzz_command(o, target, args)?,
            Run::Serve(kind) => {
                let (tally, lines) = serve::fuzz(o, target, kind)?;
                notes = lines;
                tally
            }
        };
        tally.seconds = start.elapsed().as_secs_f64();
        let failed = tally.failed(o.max_peak_mib);
        any_failed |= failed;
        let codes: Vec<String> = tally.exits.iter().map(|(c, n)| format!("{c}:{n}")).collect();
        println!(
            "{:<17} {:>8} {:>7} {:>7} {:>6} {:>7} {:>6} {:>9.1} {:>8.1}  {}",
            target.name,
            tally.runs,
            tally.panics.len(),
            tally.aborts.len(),
            tally.hangs.len(),
            tally.memory.len(),
            if failed { "NO" } else { "yes" },
            tally.peak_kib as f64 / 1024.0,
            tally.seconds,
            codes.join(" ")
        );
        for line in &notes {
            println!("    {line}");
        }
        for line in tally.panics.iter().chain(&tally.aborts).chain(&tally.hangs).chain(&tally.memory).take(10)
        {
            println!("    {line}");
        }
        std::io::stdout().flush()?;
    }
    Ok(if any_failed { 1 } else { 0 })
}

/// Keeps a failing input in `--out` and says how to run it again.
fn keep(o: &Options, target: &Target, i: u64, data: &[u8], what: &str, detail: &str) -> String {
    let dir = o.out.join(target.name);
    let path = dir.join(format!("{what}-{i}-{}", target.file_name));
    let kept = std::fs::create_dir_all(&dir).and_then(|()| std::fs::write(&path, data)).is_ok();
    format!(
        "{what} at input {i}: {detail} ({}; the input again: sandslope-fuzz --emit {} --seed {} --from {i} --to {})",
        if kept { path.display().to_string() } else { "input not kept".into() },
        target.name,
        o.seed,
        i + 1
    )
}

fn fuzz_command(o: &Options, target: &Target, args: &[&str]) -> Result<Tally> {
    let seeds = read_seeds(&o.repo, target)?;
    let scratch = tempdir()?;
    let mut tally = Tally::default();
    for i in 0..o.runs {
        let dir = scratch.join(format!("run-{}", i % 2));
        let _ = std::fs::remove_dir_all(&dir);
        work_dir(&o.repo, target, &dir)?;
        let data = input(&seeds, o.seed, i);
        let file = dir.join(target.file_name);
        std::fs::write(&file, &data)?;
        let argv: Vec<String> = args
            .iter()
            .map(|a| {
                a.replace("{in}", &file.to_string_lossy())
                    .replace("{dir}", &dir.to_string_lossy())
                    .replace("{repo}", &o.repo.to_string_lossy())
            })
            .collect();
        let mut cmd = Command::new(&o.bin);
        cmd.args(&argv).stdin(Stdio::null()).stdout(Stdio::null()).stderr(Stdio::piped());
        cmd.env("RUST_BACKTRACE", "0").env_remove("CI");
        limit_memory(&mut cmd, o.mem_limit_mib);
        let mut child = cmd.spawn().with_context(|| format!("cannot run {}", o.bin.display()))?;
        // Stderr read on a thread so a chatty child never blocks on a full pipe.
        let mut err_pipe = child.stderr.take().expect("piped");
        let reader = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = std::io::Read::read_to_string(&mut err_pipe, &mut s);
            s
        });
        let (ending, peak) = wait_with_rusage(child.id(), o.timeout)?;
        let stderr = reader.join().unwrap_or_default();
        let first_line = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or("").to_string();
        tally.runs += 1;
        tally.peak_kib = tally.peak_kib.max(peak);
        if peak > o.max_peak_mib * 1024 {
            tally.memory.push(keep(o, target, i, &data, "memory", &format!("peak {} MiB", peak / 1024)));
        }
        match ending {
            // 101: a Rust panic; any other code outside the documented table is a defect too.
            Ending::Exit(101) => tally.panics.push(keep(o, target, i, &data, "panic", &first_line)),
            Ending::Exit(c) if [0, 2, 3, 4].contains(&c) => *tally.exits.entry(c).or_default() += 1,
            Ending::Exit(c) => {
                tally.aborts.push(keep(o, target, i, &data, "exit", &format!("code {c}: {first_line}")))
            }
            Ending::Signal(s) => {
                tally.aborts.push(keep(o, target, i, &data, "abort", &format!("signal {s}: {first_line}")))
            }
            Ending::Timeout => tally.hangs.push(keep(
                o,
                target,
                i,
                &data,
                "hang",
                &format!("over {} s", o.timeout.as_secs()),
            )),
        }
    }
    let _ = std::fs::remove_dir_all(&scratch);
    Ok(tally)
}

fn tempdir() -> Result<PathBuf> {
    let dir =
        std::env::temp_dir().join(format!("sandslope-fuzz-{}-{}", std::process::id(), rand::random::<u32>()));
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

/// Runs reader inputs `from..to` in a child; returns its report lines, ending and peak.
fn reader_chunk(
    o: &Options,
    target: &Target,
    from: u64,
    to: u64,
    scratch: &Path,
) -> Result<(Vec<String>, Ending, u64)> {
    let exe = std::env::current_exe()?;
    let mut cmd = Command::new(exe);
    cmd.args(["--child", target.name, &from.to_string(), &to.to_string(), &o.seed.to_string()])
        .arg(scratch)
        .arg(&o.repo)
        .arg(o.timeout.as_secs().to_string())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::null());
    limit_memory(&mut cmd, o.mem_limit_mib);
    let mut child = cmd.spawn()?;
    let mut out_pipe = child.stdout.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut out_pipe, &mut s);
        s
    });
    // The child watches its own inputs' time; this outer limit only catches a stuck child.
    let (ending, peak) = wait_with_rusage(child.id(), o.timeout * 4 + Duration::from_secs((to - from) / 10))?;
    let lines = reader.join().unwrap_or_default().lines().map(str::to_string).collect();
    Ok((lines, ending, peak))
}

fn fuzz_reader(o: &Options, target: &Target) -> Result<Tally> {
    let seeds = read_seeds(&o.repo, target)?;
    let scratch = tempdir()?;
    work_dir(&o.repo, target, &scratch)?;
    let mut tally = Tally::default();
    let record = |tally: &mut Tally, lines: &[String]| -> Option<u64> {
        let mut hang = None;
        for l in lines {
            let mut parts = l.splitn(3, ' ');
            let (kind, a, b) =
                (parts.next().unwrap_or(""), parts.next().unwrap_or(""), parts.next().unwrap_or(""));
            let a: u64 = a.parse().unwrap_or(0);
            match kind {
                "PANIC" => tally.panics.push(keep(o, target, a, &input(&seeds, o.seed, a), "panic", b)),
                "HANG" => {
                    tally.hangs.push(keep(o, target, a, &input(&seeds, o.seed, a), "hang", b));
                    hang = Some(a);
                }
                // `COUNT ok err`: inputs read, and refused with an error (exit 2 at the CLI).
                "COUNT" => {
                    *tally.exits.entry(0).or_default() += a;
                    *tally.exits.entry(2).or_default() += b.parse::<u64>().unwrap_or(0);
                }
                _ => {}
            }
        }
        hang
    };
    let mut from = 0;
    while from < o.runs {
        let to = (from + CHUNK).min(o.runs);
        let (lines, ending, peak) = reader_chunk(o, target, from, to, &scratch)?;
        tally.peak_kib = tally.peak_kib.max(peak);
        match ending {
            Ending::Exit(0) if peak > o.max_peak_mib * 1024 => {
                // Over the memory budget: find the inputs that were, one process each.
                record(&mut tally, &lines);
                for i in from..to {
                    let (_, _, peak) = reader_chunk(o, target, i, i + 1, &scratch)?;
                    if peak > o.max_peak_mib * 1024 {
                        let data = input(&seeds, o.seed, i);
                        tally.memory.push(keep(
                            o,
                            target,
                            i,
                            &data,
                            "memory",
                            &format!("peak {} MiB", peak / 1024),
                        ));
                    }
                }
            }
            Ending::Exit(0) => {
                record(&mut tally, &lines);
            }
            Ending::Exit(124) => {
                // A hang ends its chunk: go on after the input that hung.
                let next = record(&mut tally, &lines).map_or(to, |i| i + 1);
                tally.runs += next - from;
                from = next;
                continue;
            }
            _ => {
                // The chunk died: run its inputs one by one to find which.
                for i in from..to {
                    let (lines, ending, peak) = reader_chunk(o, target, i, i + 1, &scratch)?;
                    tally.peak_kib = tally.peak_kib.max(peak);
                    match ending {
                        Ending::Exit(0 | 124) => {
                            record(&mut tally, &lines);
                        }
                        other => {
                            let data = input(&seeds, o.seed, i);
                            tally.aborts.push(keep(o, target, i, &data, "abort", &format!("{other:?}")));
                        }
                    }
                }
            }
        }
        tally.runs += to - from;
        from = to;
    }
    let _ = std::fs::remove_dir_all(&scratch);
    Ok(tally)
}

/// `--child TARGET FROM TO SEED SCRATCH REPO TIMEOUT`: runs reader inputs in this process,
/// printing `PANIC i message` and `HANG i ...` lines and, at the end, `COUNT ok err`.
fn child(args: &[String]) -> Result<()> {
    let [name, from, to, seed, scratch, repo, timeout] = args else {
        bail!("--child needs TARGET FROM TO SEED SCRATCH REPO TIMEOUT");
    };
    let target = targets::find(name).ok_or_else(|| anyhow!("no target {name}"))?;
    let Run::Reader(run) = target.run else { bail!("{name} is not a reader target") };
    let (from, to, seed): (u64, u64, u64) = (number(from, "FROM")?, number(to, "TO")?, number(seed, "SEED")?);
    let timeout = Duration::from_secs(number(timeout, "TIMEOUT")?);
    let seeds = read_seeds(Path::new(repo), target)?;
    let file = Path::new(scratch).join(target.file_name);
    std::panic::set_hook(Box::new(|_| {}));
    // A watchdog: if one input runs past the timeout, report it and end the process.
    let current = Arc::new(AtomicU64::new(u64::MAX));
    let started = Arc::new(AtomicU64::new(0));
    let epoch = Instant::now();
    {
        let (current, started) = (current.clone(), started.clone());
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_millis(50));
            let i = current.load(Ordering::SeqCst);
            let t0 = started.load(Ordering::SeqCst);
            if i != u64::MAX && epoch.elapsed().as_millis() as u64 > t0 + timeout.as_millis() as u64 {
                println!("HANG {i} over {} s", timeout.as_secs());
                let _ = std::io::stdout().flush();
                std::process::exit(124);
            }
        });
    }
    let (mut ok, mut err) = (0u64, 0u64);
    for i in from..to {
        let data = input(&seeds, seed, i);
        std::fs::write(&file, &data)?;
        started.store(epoch.elapsed().as_millis() as u64, Ordering::SeqCst);
        current.store(i, Ordering::SeqCst);
        match std::panic::catch_unwind(|| run(&file)) {
            Ok(Ok(())) => ok += 1,
            Ok(Err(_)) => err += 1,
            Err(p) => {
                let msg = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                println!("PANIC {i} {}", msg.replace('\n', " "));
            }
        }
        current.store(u64::MAX, Ordering::SeqCst);
    }
    println!("COUNT {ok} {err}");
    Ok(())
}

/// `--emit TARGET --from I --to J --dir DIR`: writes inputs I..J as files (for the Python
/// readers' fuzz, scripts/fuzz_python.py, and to reproduce a failure).
fn emit(args: &[String]) -> Result<()> {
    let (mut from, mut to, mut dir, mut seed) = (0u64, 1u64, PathBuf::from("."), 1u64);
    let name = args.first().ok_or_else(|| anyhow!("--emit needs a TARGET\n{}", usage()))?;
    let target = targets::find(name).ok_or_else(|| anyhow!("no target `{name}`\n{}", usage()))?;
    let repo = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut i = 1;
    while i < args.len() {
        let a = args[i].as_str();
        match a {
            "--from" => from = number(value(args, &mut i, a)?, a)?,
            "--to" => to = number(value(args, &mut i, a)?, a)?,
            "--dir" => dir = PathBuf::from(value(args, &mut i, a)?),
            "--seed" => seed = number(value(args, &mut i, a)?, a)?,
            other => bail!("unknown option {other}\n{}", usage()),
        }
        i += 1;
    }
    let seeds = read_seeds(&repo, target)?;
    std::fs::create_dir_all(&dir)?;
    for i in from..to {
        let data = match target.run {
            Run::Serve(kind) => serve::emitted(kind, &seeds, seed, i),
            _ => input(&seeds, seed, i),
        };
        std::fs::write(dir.join(format!("{i}-{}", target.file_name)), data)?;
    }
    Ok(())
}
