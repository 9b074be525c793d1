//! The two storages of a ROS 2 bag, read start to end: MCAP through the `mcap` crate's
//! streaming reader (chunks decompressed one at a time, their CRCs checked before any of
//! their messages is used), SQLite3 through `rusqlite` (one row at a time).

use std::cell::Cell;
use std::io::Read;
use std::path::Path;
use std::rc::Rc;

use anyhow::{anyhow, bail, Result};

use super::{BagMessage, BagTopic, Location, MAX_MESSAGES};

/// Counts the bytes read, so that an error can say how far into the file it was.
struct Counting<R> {
    inner: R,
    read: Rc<Cell<u64>>,
}

impl<R: Read> Read for Counting<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.read.set(self.read.get() + n as u64);
        Ok(n)
    }
}

/// The longest record the MCAP reader accepts, bytes: 256 MiB, and never more than 64 times
/// the file (a chunk compresses, but no record of a small file can be gigabytes long), so a
/// length field cannot make the reader allocate more than the file could justify.
fn record_limit(file_len: u64) -> usize {
    const CAP: u64 = 256 << 20;
    file_len.saturating_mul(64).clamp(1 << 20, CAP) as usize
}

/// Counts a message on `name`, checking that the topic keeps one type; returns its index.
fn count(
    topics: &mut Vec<BagTopic>,
    name: &str,
    type_name: &str,
    encoding: &str,
    at: &Location,
) -> Result<u64> {
    match topics.iter_mut().find(|t| t.name == name) {
        Some(t) => {
            if t.type_name != type_name {
                bail!("{at}: topic `{name}` changes type from {} to {type_name}", t.type_name);
            }
            t.messages += 1;
            Ok(t.messages - 1)
        }
        None => {
            topics.push(BagTopic {
                name: name.into(),
                type_name: type_name.into(),
                encoding: encoding.into(),
                messages: 1,
            });
            Ok(0)
        }
    }
}

fn check_message(m: &BagMessage<'_>, encoding: &str) -> Result<()> {
    if encoding != "cdr" {
        bail!(
            "{}: topic `{}`: message encoding `{encoding}`; ROS 2 bags hold `cdr` (sandslope reads no other)",
            m.at,
            m.topic
        );
    }
    if m.index >= MAX_MESSAGES {
        bail!("{}: topic `{}`: more than {MAX_MESSAGES} messages; split the bag", m.at, m.topic);
    }
    Ok(())
}

/// Reads one MCAP file.
pub(super) fn scan_mcap(
    path: &Path,
    topic: Option<&str>,
    topics: &mut Vec<BagTopic>,
    on_message: &mut dyn FnMut(&BagMessage<'_>) -> Result<()>,
) -> Result<()> {
    let file = std::fs::File::open(path).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let len = file.metadata().map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?.len();
    let read = Rc::new(Cell::new(0u64));
    let source = Counting { inner: std::io::BufReader::with_capacity(1 << 16, file), read: read.clone() };
    let options = mcap::sans_io::LinearReaderOptions::default()
        .with_prevalidate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_validate_summary_section_crc(true)
        .with_record_length_limit(record_limit(len));
    let reader = mcap::io::MessageReader::new_with_options(source, options);
    for message in reader {
        let here = Location { file: path, offset: read.get(), row: false };
        let message = message.map_err(|e| {
            let why = match &e {
                mcap::McapError::UnexpectedEof | mcap::McapError::BadFooter => {
                    format!("{e}: the file is cut short (a recording stopped before it was closed: `mcap recover` or `ros2 bag reindex` may save it)")
                }
                mcap::McapError::BadChunkCrc { .. } | mcap::McapError::BadDataCrc { .. } => {
                    format!("{e}: the file is damaged")
                }
                mcap::McapError::RecordTooLarge { .. } | mcap::McapError::ChunkTooLarge(_) => {
                    format!("{e} (at most {} bytes for a file of {len} bytes)", record_limit(len))
                }
                _ => e.to_string(),
            };
            match topic {
                Some(t) => anyhow!("{here} (reading topic `{t}`): {why}"),
                None => anyhow!("{here}: {why}"),
            }
        })?;
        let channel = &message.channel;
        let type_name = channel.schema.as_ref().map_or("", |s| s.name.as_str());
        let index = count(topics, &channel.topic, type_name, &channel.message_encoding, &here)?;
        if topic == Some(channel.topic.as_str()) {
            let m = BagMessage {
                topic: &channel.topic,
                type_name,
                log_time_ns: message.log_time,
                data: &message.data,
                at: here,
                index,
            };
            check_message(&m, &channel.message_encoding)?;
            on_message(&m)?;
        }
    }
    Ok(())
}

/// Reads one SQLite3 storage file (tables `topics` and `messages`, as rosbag2 writes them).
#[cfg(feature = "bags-sqlite")]
pub(super) fn scan_sqlite(
    path: &Path,
    topic: Option<&str>,
    topics: &mut Vec<BagTopic>,
    on_message: &mut dyn FnMut(&BagMessage<'_>) -> Result<()>,
) -> Result<()> {
    use rusqlite::{Connection, OpenFlags};
    let db_error = |e: rusqlite::Error| {
        anyhow!("{}: {e} (not a rosbag2 SQLite3 storage file, or a damaged one)", path.display())
    };
    let conn =
        Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX)
            .map_err(db_error)?;
    let mut stmt = conn
        .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")
        .map_err(db_error)?;
    let declared: Vec<(i64, String, String, String)> = stmt
        .query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?)))
        .map_err(db_error)?
        .collect::<rusqlite::Result<_>>()
        .map_err(db_error)?;
    let mut stmt =
        conn.prepare("SELECT id, topic_id, timestamp, data FROM messages ORDER BY id").map_err(db_error)?;
    let mut rows = stmt.query([]).map_err(db_error)?;
    while let Some(row) = rows.next().map_err(db_error)? {
        let id: i64 = row.get(0).map_err(db_error)?;
        let topic_id: i64 = row.get(1).map_err(db_error)?;
        let at = Location { file: path, offset: id.max(0) as u64, row: true };
        let timestamp: i64 = row.get(2).map_err(db_error)?;
        let Some((_, name, type_name, encoding)) = declared.iter().find(|t| t.0 == topic_id) else {
            bail!("{at}: topic_id {topic_id} is not in the table topics");
        };
        let index = count(topics, name, type_name, encoding, &at)?;
        if topic == Some(name.as_str()) {
            let data = row.get_ref(3).map_err(db_error)?.as_blob().map_err(|e| anyhow!("{at}: data: {e}"))?;
            if timestamp < 0 {
                bail!("{at}: timestamp {timestamp} ns is before 1970");
            }
            let m = BagMessage { topic: name, type_name, log_time_ns: timestamp as u64, data, at, index };
            check_message(&m, encoding)?;
            on_message(&m)?;
        }
    }
    // Topics without messages are listed too (a recorder that subscribed to them).
    for (_, name, type_name, encoding) in declared {
        if !topics.iter().any(|t| t.name == name) {
            topics.push(BagTopic { name, type_name, encoding, messages: 0 });
        }
    }
    Ok(())
}

/// Without the `bags-sqlite` feature, a `.db3` is named and refused.
#[cfg(not(feature = "bags-sqlite"))]
pub(super) fn scan_sqlite(
    path: &Path,
    _topic: Option<&str>,
    _topics: &mut Vec<BagTopic>,
    _on_message: &mut dyn FnMut(&BagMessage<'_>) -> Result<()>,
) -> Result<()> {
    bail!(
        "{}: an SQLite3 bag, but this sandslope was built without the `bags-sqlite` feature; convert it to \
         MCAP (`ros2 bag convert`) or rebuild with the default features",
        path.display()
    )
}
