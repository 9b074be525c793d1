//! # sandslope-bag
//!
//! ROS 2 bags as inputs (docs/bags.md): a bag folder as `ros2 bag record` writes it
//! (`metadata.yaml` beside its `.mcap` or `.db3` files), or a single `.mcap` or `.db3` file,
//! with CDR-encoded messages.
//!
//! - [`scan`] reads a bag once, start to end, handing each message of the topic asked for to
//!   a callback and counting every topic's messages: memory stays that of one chunk (MCAP,
//!   through the `mcap` crate's streaming reader, CRCs checked) or one row (SQLite3, through
//!   `rusqlite`), whatever the bag's size.
//! - [`messages`] holds the message types and their CDR decoding (`cdr-encoding`).
//! - [`series`] turns a topic of poses, odometry or a TF frame into a body's positions on a
//!   regular grid of times (`track --topic --frame`; sandslope-io's `bag_series` makes them a
//!   motion capture and reads joint states as a servo log), [`wrench`] a load-cell series from
//!   wrenches (`fit`).
//!
//! Every error names the file, the topic and where in the file (the byte offset reached in an
//! MCAP file, the message's row in a `.db3`), and nothing is returned from a bag that fails
//! part-way: a truncated file, a chunk whose CRC does not match, an encoding other than CDR, a
//! topic of another type, a declared message count no file of that size could hold.
//!
//! Nothing here needs the `sandslope` library, so a first build compiles this crate beside it.

#![warn(missing_docs)]

pub mod messages;
mod metadata;
pub mod series;
mod storage;
mod tf;
pub mod wrench;

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};

/// One topic of a bag: name, type, encoding and how many messages it holds.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct BagTopic {
    /// Topic name (`/mocap/robot/pose`).
    pub name: String,
    /// Message type as recorded (`geometry_msgs/msg/PoseStamped`).
    #[serde(rename = "type")]
    pub type_name: String,
    /// Serialisation (`cdr` for ROS 2).
    pub encoding: String,
    /// Messages read on it.
    pub messages: u64,
}

/// One message as [`scan`] hands it over.
#[derive(Debug, Clone, Copy)]
pub struct BagMessage<'a> {
    /// Its topic.
    pub topic: &'a str,
    /// Its type as recorded.
    pub type_name: &'a str,
    /// The time the recorder received it, ns.
    pub log_time_ns: u64,
    /// The serialised message (CDR with its 4-byte encapsulation header).
    pub data: &'a [u8],
    /// Where it is: the storage file and, in it, the byte offset reached (MCAP) or the row
    /// (SQLite3).
    pub at: Location<'a>,
    /// Its index among its topic's messages, from 0.
    pub index: u64,
}

/// A message's time, ns: its header's stamp, or the time the recorder received it where the
/// stamp is zero (a publisher that never set it).
pub fn stamp_ns(header: &messages::Header, m: &BagMessage<'_>) -> i64 {
    match header.stamp.nanos() {
        0 => m.log_time_ns.min(i64::MAX as u64) as i64,
        ns => ns,
    }
}

/// Where a message or an error is in a bag.
#[derive(Debug, Clone, Copy)]
pub struct Location<'a> {
    /// The storage file.
    pub file: &'a Path,
    /// Byte offset reached (MCAP: the message lies before it) or row id (SQLite3).
    pub offset: u64,
    /// Whether `offset` is a row id.
    pub row: bool,
}

impl std::fmt::Display for Location<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.row {
            write!(f, "{}: row {} of table messages", self.file.display(), self.offset)
        } else {
            write!(f, "{}: at or before byte offset {}", self.file.display(), self.offset)
        }
    }
}

/// Storage of a bag's files.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Storage {
    /// MCAP (rosbag2's default since Iron).
    Mcap,
    /// SQLite3 (`.db3`, rosbag2's default before Iron).
    Sqlite3,
}

/// A bag opened: its storage files in order.
#[derive(Debug, Clone)]
pub struct Bag {
    /// What the user named (a folder or a file).
    pub path: PathBuf,
    /// Storage.
    pub storage: Storage,
    /// The storage files, in recording order.
    pub files: Vec<PathBuf>,
}

/// The first bytes of an MCAP file.
const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// The first bytes of an SQLite3 database.
const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";

/// Most messages one topic may hand over (a day at 120 Hz is 10.4 million).
pub const MAX_MESSAGES: u64 = 20_000_000;

/// Whether `path` is a bag: a folder holding `metadata.yaml`, or a file named `.mcap` or
/// `.db3`, or starting with MCAP's or SQLite's magic bytes.
pub fn is_bag(path: &Path) -> bool {
    if path.is_dir() {
        return path.join("metadata.yaml").is_file();
    }
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if matches!(ext.as_deref(), Some("mcap" | "db3")) {
        return true;
    }
    magic(path).is_some()
}

fn magic(path: &Path) -> Option<Storage> {
    use std::io::Read;
    let mut head = [0u8; 16];
    let mut f = std::fs::File::open(path).ok()?;
    let n = f.read(&mut head).ok()?;
    if head[..n].starts_with(MCAP_MAGIC) {
        Some(Storage::Mcap)
    } else if head[..n].starts_with(SQLITE_MAGIC) {
        Some(Storage::Sqlite3)
    } else {
        None
    }
}

/// Opens a bag: a folder with `metadata.yaml`, or one `.mcap` or `.db3` file (told apart by
/// their first bytes). Errors name the file and the key.
pub fn open(path: &Path) -> Result<Bag> {
    if path.is_dir() {
        return open_folder(path);
    }
    let storage = match magic(path) {
        Some(s) => s,
        None => {
            std::fs::metadata(path).with_context(|| format!("cannot read {}", path.display()))?;
            bail!(
                "{}: not a ROS 2 bag: an MCAP file starts with the bytes 89 4D 43 41 50 30 (\\x89MCAP0) and an \
                 SQLite3 one with `SQLite format 3`",
                path.display()
            )
        }
    };
    Ok(Bag { path: path.to_path_buf(), storage, files: vec![path.to_path_buf()] })
}

fn open_folder(dir: &Path) -> Result<Bag> {
    let meta_path = dir.join("metadata.yaml");
    let text = sandslope_files::read_text(&meta_path)
        .with_context(|| format!("{}: not a ROS 2 bag folder (no readable metadata.yaml)", dir.display()))?;
    let info = metadata::parse(&text).map_err(|e| anyhow!("{}: {e}", meta_path.display()))?;
    let storage = match info.storage_identifier.as_str() {
        "mcap" => Storage::Mcap,
        "sqlite3" => Storage::Sqlite3,
        other => bail!(
            "{}: storage_identifier `{other}` is not one sandslope reads (mcap or sqlite3)",
            meta_path.display()
        ),
    };
    if !info.compression_mode.is_empty() && !info.compression_format.is_empty() {
        bail!(
            "{}: compression_mode `{}` with compression_format `{}`: the files are compressed whole; \
             decompress the bag first (`ros2 bag convert`), or record with the MCAP storage's own chunk \
             compression (`--storage-preset-profile zstd_fast`), which sandslope reads",
            meta_path.display(),
            info.compression_mode,
            info.compression_format
        );
    }
    if info.relative_file_paths.is_empty() {
        bail!("{}: relative_file_paths lists no storage file", meta_path.display());
    }
    let mut files = Vec::with_capacity(info.relative_file_paths.len().min(10_000));
    let mut bytes = 0u64;
    for rel in &info.relative_file_paths {
        let rel_path = Path::new(rel);
        // rosbag2 writes the name inside the folder (older versions the folder's own name
        // before it); a path out of the folder is refused.
        let name = rel_path.file_name().ok_or_else(|| {
            anyhow!("{}: relative_file_paths entry `{rel}` is not a file name", meta_path.display())
        })?;
        if rel_path.components().any(|c| matches!(c, std::path::Component::ParentDir))
            || rel_path.is_absolute()
        {
            bail!("{}: relative_file_paths entry `{rel}` points out of the bag folder", meta_path.display());
        }
        let file = dir.join(name);
        let len = std::fs::metadata(&file)
            .map_err(|e| {
                anyhow!(
                    "{}: relative_file_paths names `{rel}`, but {}: {e}",
                    meta_path.display(),
                    file.display()
                )
            })?
            .len();
        bytes += len;
        files.push(file);
    }
    // A declared count no file of this size could hold (every stored message takes more
    // than 8 bytes) is a damaged or forged metadata.yaml, said before anything is read.
    let most = bytes / 8 + 1;
    if let Some(n) = info.message_count.filter(|&n| n > most) {
        bail!(
            "{}: message_count = {n}, but the storage files hold {bytes} bytes (at most {most} messages); \
             a damaged metadata.yaml (`ros2 bag reindex` rewrites it)",
            meta_path.display()
        );
    }
    for t in &info.topics_with_message_count {
        if t.message_count > most {
            bail!(
                "{}: topic `{}`: message_count = {}, but the storage files hold {bytes} bytes (at most {most} \
                 messages); a damaged metadata.yaml (`ros2 bag reindex` rewrites it)",
                meta_path.display(),
                t.name,
                t.message_count
            );
        }
    }
    Ok(Bag { path: dir.to_path_buf(), storage, files })
}

/// Reads `bag` start to end, calling `on_message` for every message on `topic` (none when
/// `None`: a listing), and returns every topic with its count. The first error (the file's,
/// or one `on_message` returns) ends the read.
pub fn scan(
    bag: &Bag,
    topic: Option<&str>,
    on_message: &mut dyn FnMut(&BagMessage<'_>) -> Result<()>,
) -> Result<Vec<BagTopic>> {
    let mut topics: Vec<BagTopic> = Vec::new();
    for file in &bag.files {
        match bag.storage {
            Storage::Mcap => storage::scan_mcap(file, topic, &mut topics, on_message)?,
            Storage::Sqlite3 => storage::scan_sqlite(file, topic, &mut topics, on_message)?,
        }
    }
    Ok(topics)
}

/// The bag's topics with their types and counts (one read of the whole bag).
pub fn topics(path: &Path) -> Result<Vec<BagTopic>> {
    let bag = open(path)?;
    scan(&bag, None, &mut |_| Ok(()))
}

/// The topics as a list for a message: `/a (geometry_msgs/msg/PoseStamped, 1200 messages)`,
/// those of the `wanted` types first.
pub fn describe_topics(topics: &[BagTopic], wanted: &[&str]) -> String {
    let fits = |t: &BagTopic| wanted.iter().any(|w| messages::same_type(&t.type_name, w));
    let mut sorted: Vec<&BagTopic> = topics.iter().collect();
    sorted.sort_by_key(|t| !fits(t));
    if sorted.is_empty() {
        return "the bag has no topics".into();
    }
    sorted
        .iter()
        .map(|t| format!("{} ({}, {} messages)", t.name, t.type_name, t.messages))
        .collect::<Vec<_>>()
        .join("; ")
}
