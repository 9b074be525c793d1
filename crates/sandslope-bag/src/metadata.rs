//! `metadata.yaml` as rosbag2 writes it, the keys sandslope uses, read through the
//! `granit-parser` YAML event parser (the parser beneath serde-saphyr, without its
//! deserialiser, which took 24 s of a first build's CPU for these six keys). Other keys are
//! ignored; an error names the key and its line.

use granit_parser::{Event, Parser, ScalarStyle, Span};

/// The keys of `rosbag2_bagfile_information` sandslope uses (absent ones empty).
#[derive(Debug, Default)]
pub(crate) struct Information {
    pub storage_identifier: String,
    pub relative_file_paths: Vec<String>,
    pub message_count: Option<u64>,
    pub compression_format: String,
    pub compression_mode: String,
    pub topics_with_message_count: Vec<TopicCount>,
}

/// One entry of `topics_with_message_count`.
#[derive(Debug)]
pub(crate) struct TopicCount {
    /// `topic_metadata.name`.
    pub name: String,
    pub message_count: u64,
}

/// A YAML node with the line it starts on.
enum Node {
    /// A scalar; `None` for YAML's null (`~`, `null`, nothing).
    Scalar(Option<String>, usize),
    Seq(Vec<Node>, usize),
    Map(Vec<(String, Node)>, usize),
}

/// Nesting deeper than this is no rosbag2 file (it nests four levels).
const MAX_DEPTH: usize = 32;

type Events<'a> = Parser<'a, granit_parser::StrInput<'a>>;

fn next_event<'a>(events: &mut Events<'a>) -> Result<(Event<'a>, Span), String> {
    match events.next() {
        Some(Ok(e)) => Ok(e),
        Some(Err(e)) => Err(e.to_string()),
        None => Err("the YAML ends early".into()),
    }
}

/// The node that starts with `first`, its events read from `events`.
fn node<'a>(events: &mut Events<'a>, first: (Event<'a>, Span), depth: usize) -> Result<Node, String> {
    let line = first.1.start.line();
    if depth > MAX_DEPTH {
        return Err(format!("line {line}: nested more than {MAX_DEPTH} levels deep"));
    }
    match first.0 {
        Event::Scalar(v, style, _, _) => {
            let null =
                style == ScalarStyle::Plain && matches!(v.as_ref(), "" | "~" | "null" | "Null" | "NULL");
            Ok(Node::Scalar((!null).then(|| v.into_owned()), line))
        }
        Event::SequenceStart(..) => {
            let mut items = Vec::new();
            loop {
                let e = next_node_event(events)?;
                if matches!(e.0, Event::SequenceEnd) {
                    return Ok(Node::Seq(items, line));
                }
                items.push(node(events, e, depth + 1)?);
            }
        }
        Event::MappingStart(..) => {
            let mut entries = Vec::new();
            loop {
                let e = next_node_event(events)?;
                if matches!(e.0, Event::MappingEnd) {
                    return Ok(Node::Map(entries, line));
                }
                let key_line = e.1.start.line();
                let key = match node(events, e, depth + 1)? {
                    Node::Scalar(Some(k), _) => k,
                    _ => return Err(format!("line {key_line}: a key that is not a plain string")),
                };
                let value = next_node_event(events)?;
                entries.push((key, node(events, value, depth + 1)?));
            }
        }
        Event::Alias(..) | Event::UnresolvedAlias(..) => {
            Err(format!("line {line}: a YAML alias (`*name`), which rosbag2 does not write"))
        }
        other => Err(format!("line {line}: unexpected YAML {other:?}")),
    }
}

/// The next event that is part of the document's structure: a node, a collection's end, or
/// the stream's and document's bounds (not presentation metadata: an anchor's name, a comment
/// where the parser's `comments` feature is on).
fn next_node_event<'a>(events: &mut Events<'a>) -> Result<(Event<'a>, Span), String> {
    loop {
        let e = next_event(events)?;
        let structure = matches!(
            e.0,
            Event::SequenceEnd
                | Event::MappingEnd
                | Event::StreamStart
                | Event::StreamEnd
                | Event::DocumentStart(..)
                | Event::DocumentEnd
        );
        if e.0.is_node() || structure {
            return Ok(e);
        }
    }
}

fn get<'n>(entries: &'n [(String, Node)], key: &str) -> Option<&'n Node> {
    entries.iter().find(|(k, _)| k == key).map(|(_, v)| v)
}

fn string(node: Option<&Node>, key: &str) -> Result<String, String> {
    match node {
        None | Some(Node::Scalar(None, _)) => Ok(String::new()),
        Some(Node::Scalar(Some(s), _)) => Ok(s.clone()),
        Some(Node::Seq(_, l) | Node::Map(_, l)) => Err(format!("line {l}: `{key}` must be a string")),
    }
}

fn count(node: Option<&Node>, key: &str) -> Result<Option<u64>, String> {
    match node {
        None | Some(Node::Scalar(None, _)) => Ok(None),
        Some(Node::Scalar(Some(s), l)) => s
            .parse::<u64>()
            .map(Some)
            .map_err(|_| format!("line {l}: `{key}` = `{s}` must be a whole number of messages (0 or more)")),
        Some(Node::Seq(_, l) | Node::Map(_, l)) => Err(format!("line {l}: `{key}` must be a whole number")),
    }
}

fn list<'n>(node: Option<&'n Node>, key: &str) -> Result<&'n [Node], String> {
    match node {
        None | Some(Node::Scalar(None, _)) => Ok(&[]),
        Some(Node::Seq(items, _)) => Ok(items),
        Some(Node::Scalar(_, l) | Node::Map(_, l)) => Err(format!("line {l}: `{key}` must be a list")),
    }
}

/// Reads `text` (a `metadata.yaml`); the error says what is wrong and on which line.
pub(crate) fn parse(text: &str) -> Result<Information, String> {
    let mut events = Parser::new_from_str(text);
    let root = loop {
        let e = next_node_event(&mut events)?;
        match e.0 {
            Event::StreamStart | Event::DocumentStart(..) => continue,
            Event::StreamEnd => {
                return Err("missing field `rosbag2_bagfile_information` (the file is empty)".into())
            }
            _ => break node(&mut events, e, 0)?,
        }
    };
    let Node::Map(top, _) = &root else {
        return Err("missing field `rosbag2_bagfile_information` (the file is not a mapping)".into());
    };
    let info = match get(top, "rosbag2_bagfile_information") {
        Some(Node::Map(info, _)) => info,
        Some(Node::Scalar(_, l) | Node::Seq(_, l)) => {
            return Err(format!("line {l}: `rosbag2_bagfile_information` must be a mapping"))
        }
        None => return Err("missing field `rosbag2_bagfile_information`".into()),
    };
    let mut out = Information {
        storage_identifier: string(get(info, "storage_identifier"), "storage_identifier")?,
        message_count: count(get(info, "message_count"), "message_count")?,
        compression_format: string(get(info, "compression_format"), "compression_format")?,
        compression_mode: string(get(info, "compression_mode"), "compression_mode")?,
        ..Information::default()
    };
    for p in list(get(info, "relative_file_paths"), "relative_file_paths")? {
        out.relative_file_paths.push(string(Some(p), "relative_file_paths")?);
    }
    for t in list(get(info, "topics_with_message_count"), "topics_with_message_count")? {
        let Node::Map(t, l) = t else {
            return Err("`topics_with_message_count` must be a list of mappings".into());
        };
        let name = match get(t, "topic_metadata") {
            Some(Node::Map(m, _)) => match get(m, "name") {
                Some(Node::Scalar(Some(n), _)) => n.clone(),
                _ => return Err(format!("line {l}: missing field `topic_metadata.name`")),
            },
            _ => return Err(format!("line {l}: missing field `topic_metadata`")),
        };
        let message_count = count(get(t, "message_count"), "message_count")?.unwrap_or(0);
        out.topics_with_message_count.push(TopicCount { name, message_count });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A metadata.yaml as rosbag2 (Jazzy) writes it, cut to the keys around those read.
    const JAZZY: &str = "rosbag2_bagfile_information:
  version: 9
  storage_identifier: mcap
  duration:
    nanoseconds: 2000000000
  message_count: 12 # all topics
  topics_with_message_count:
    - topic_metadata:
        name: /tf
        type: tf2_msgs/msg/TFMessage
        offered_qos_profiles:
          - history: 3
      message_count: 10
    - topic_metadata: {name: /joint_states, type: sensor_msgs/msg/JointState}
      message_count: 2
  compression_format: \"\"
  compression_mode: \"\"
  relative_file_paths:
    - run_0.mcap
  files: []
";

    #[test]
    fn reads_the_keys_rosbag2_writes() {
        let i = parse(JAZZY).unwrap();
        assert_eq!(i.storage_identifier, "mcap");
        assert_eq!(i.message_count, Some(12));
        assert_eq!(i.relative_file_paths, vec!["run_0.mcap"]);
        assert_eq!((i.compression_format.as_str(), i.compression_mode.as_str()), ("", ""));
        let t: Vec<_> =
            i.topics_with_message_count.iter().map(|t| (t.name.as_str(), t.message_count)).collect();
        assert_eq!(t, vec![("/tf", 10), ("/joint_states", 2)]);
    }

    #[test]
    fn errors_name_the_key_and_line() {
        let e = parse(&JAZZY.replace("message_count: 12", "message_count: twelve")).unwrap_err();
        assert!(e.contains("line 6") && e.contains("`message_count` = `twelve`"), "{e}");
        let e = parse("version: 9\n").unwrap_err();
        assert!(e.contains("missing field `rosbag2_bagfile_information`"), "{e}");
        assert!(parse("").unwrap_err().contains("missing field"));
        assert!(parse("a: [").is_err());
        let deep = "a: ".to_string() + &"[".repeat(100) + &"]".repeat(100);
        assert!(parse(&deep).unwrap_err().contains("nested more than 32"));
        let e = parse("rosbag2_bagfile_information:\n  relative_file_paths: a.mcap\n").unwrap_err();
        assert!(e.contains("line 2: `relative_file_paths` must be a list"), "{e}");
    }
}
