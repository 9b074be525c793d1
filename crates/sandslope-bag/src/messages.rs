//! The ROS 2 messages sandslope reads from bags and writes to MCAP, as serde types in the
//! field order of their `.msg` definitions (CDR is that order, aligned), their type names
//! and their `ros2msg` definitions (what an MCAP's schema record embeds, so that any reader
//! decodes the messages without ROS installed).
//!
//! Decoding and encoding are the `cdr-encoding` crate's: this module only checks the
//! 4-byte encapsulation header (CDR little- or big-endian, the two ROS 2 writes) in front.

use byteorder::{BigEndian, LittleEndian};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// `builtin_interfaces/Time`: seconds and nanoseconds since the epoch (or of the bag's clock).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds, 0 to 999 999 999.
    pub nanosec: u32,
}

impl Time {
    /// The time in nanoseconds (negative before the clock's zero).
    pub fn nanos(self) -> i64 {
        i64::from(self.sec) * 1_000_000_000 + i64::from(self.nanosec)
    }

    /// A time from nanoseconds (`sec` saturating at the `i32` range).
    pub fn from_nanos(ns: i64) -> Time {
        let sec = ns.div_euclid(1_000_000_000);
        Time {
            sec: sec.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32,
            nanosec: ns.rem_euclid(1_000_000_000) as u32,
        }
    }
}

/// `std_msgs/Header`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// When the data were measured.
    pub stamp: Time,
    /// The frame the data are in.
    pub frame_id: String,
}

/// `geometry_msgs/Point` (also the layout of `Vector3`), m.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Point {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/Quaternion`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
    }
}

impl Quaternion {
    /// The rotation by `angle` rad about the unit axis `axis`.
    pub fn about(axis: [f64; 3], angle: f64) -> Quaternion {
        let (s, c) = (angle / 2.0).sin_cos();
        Quaternion { x: axis[0] * s, y: axis[1] * s, z: axis[2] * s, w: c }
    }
}

/// `geometry_msgs/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position, m.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/PoseStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Header.
    pub header: Header,
    /// Pose.
    pub pose: Pose,
}

/// `geometry_msgs/Transform`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation, m (a `Vector3`).
    pub translation: Point,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/TransformStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Header (its frame is the parent).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's pose in the parent.
    pub transform: Transform,
}

/// `tf2_msgs/TFMessage`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// Transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `geometry_msgs/PoseWithCovariance` (6 x 6 covariance, row-major).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// Pose.
    pub pose: Pose,
    /// Covariance (36 numbers, as 6 rows: serde's arrays stop at 32).
    pub covariance: [[f64; 6]; 6],
}

/// `geometry_msgs/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear, m/s.
    pub linear: Point,
    /// Angular, rad/s.
    pub angular: Point,
}

/// `geometry_msgs/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// Twist.
    pub twist: Twist,
    /// Covariance.
    pub covariance: [[f64; 6]; 6],
}

/// `nav_msgs/Odometry`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// Header.
    pub header: Header,
    /// The body's frame.
    pub child_frame_id: String,
    /// Pose.
    pub pose: PoseWithCovariance,
    /// Twist.
    pub twist: TwistWithCovariance,
}

/// `sensor_msgs/JointState`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions, rad.
    pub position: Vec<f64>,
    /// Velocities, rad/s.
    pub velocity: Vec<f64>,
    /// Efforts (N m by the message's documentation; see docs/bags.md for currents).
    pub effort: Vec<f64>,
}

/// `geometry_msgs/Wrench`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force, N.
    pub force: Point,
    /// Torque, N m.
    pub torque: Point,
}

/// `geometry_msgs/WrenchStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct WrenchStamped {
    /// Header.
    pub header: Header,
    /// Wrench.
    pub wrench: Wrench,
}

/// `nav_msgs/MapMetaData`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct MapMetaData {
    /// When the map was loaded.
    pub map_load_time: Time,
    /// Cell size, m.
    pub resolution: f32,
    /// Cells per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// The pose of cell (0, 0)'s corner in the map's frame.
    pub origin: Pose,
}

/// `nav_msgs/OccupancyGrid`: row-major from the origin, 0 to 100 or -1 (unknown).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct OccupancyGrid {
    /// Header.
    pub header: Header,
    /// Geometry.
    pub info: MapMetaData,
    /// Cells.
    pub data: Vec<i8>,
}

/// `nav_msgs/Path`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct NavPath {
    /// Header.
    pub header: Header,
    /// Poses along the path.
    pub poses: Vec<PoseStamped>,
}

/// `std_msgs/ColorRGBA`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ColorRgba {
    /// Red, 0 to 1.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity.
    pub a: f32,
}

/// `builtin_interfaces/Duration`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Duration {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds.
    pub nanosec: u32,
}

/// `visualization_msgs/Marker` (the Humble definition, which the schema embeds).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Marker {
    /// Header.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Shape (0 arrow).
    #[serde(rename = "type")]
    pub kind: i32,
    /// 0 add or modify.
    pub action: i32,
    /// Pose.
    pub pose: Pose,
    /// Scale.
    pub scale: Point,
    /// Colour.
    pub color: ColorRgba,
    /// How long it lasts (0: until replaced).
    pub lifetime: Duration,
    /// Whether it follows its frame.
    pub frame_locked: bool,
    /// An arrow's start and end.
    pub points: Vec<Point>,
    /// Per-point colours.
    pub colors: Vec<ColorRgba>,
    /// Text.
    pub text: String,
    /// Mesh.
    pub mesh_resource: String,
    /// Mesh materials.
    pub mesh_use_embedded_materials: bool,
}

/// `visualization_msgs/MarkerArray`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MarkerArray {
    /// Markers.
    pub markers: Vec<Marker>,
}

/// `std_msgs/String` (the drive's verdict and the run's notes).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct StringMsg {
    /// Text.
    pub data: String,
}

/// `std_msgs/Float64MultiArray` without its layout's dimensions (an empty layout): the live
/// estimate's numbers, named in the channel's metadata.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Float64Array {
    /// Layout: its dimensions (empty) and data offset.
    pub layout: ArrayLayout,
    /// Numbers.
    pub data: Vec<f64>,
}

/// `std_msgs/MultiArrayLayout` with no dimensions.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ArrayLayout {
    /// Dimensions (always empty here).
    pub dim: Vec<ArrayDimension>,
    /// Padding elements at the front.
    pub data_offset: u32,
}

/// `std_msgs/MultiArrayDimension`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ArrayDimension {
    /// Label.
    pub label: String,
    /// Size.
    pub size: u32,
    /// Stride.
    pub stride: u32,
}

/// A message type sandslope knows: its ROS 2 name and its `ros2msg` definition.
pub trait RosMessage: Serialize + DeserializeOwned {
    /// The type's name as bags record it (`geometry_msgs/msg/PoseStamped`).
    const TYPE: &'static str;
    /// The definition as an MCAP `ros2msg` schema holds it: the type's own fields, then each
    /// type it uses after a line of `=` and `MSG: package/Type`.
    fn definition() -> String;
}

/// The type names a bag may spell one type with: `pkg/msg/Type` (ROS 2) or `pkg/Type`.
pub fn same_type(recorded: &str, ours: &str) -> bool {
    recorded == ours || recorded.replace("/msg/", "/") == ours.replace("/msg/", "/")
}

const SEPARATOR: &str = "================================================================================\n";

fn with_deps(own: &str, deps: &[&str]) -> String {
    let mut s = own.to_string();
    for d in deps {
        let text = match *d {
            "std_msgs/Header" => HEADER,
            "builtin_interfaces/Time" => TIME,
            "builtin_interfaces/Duration" => DURATION,
            "geometry_msgs/Point" => POINT,
            "geometry_msgs/Vector3" => VECTOR3,
            "geometry_msgs/Quaternion" => QUATERNION,
            "geometry_msgs/Pose" => POSE,
            "geometry_msgs/PoseStamped" => POSE_STAMPED,
            "geometry_msgs/Transform" => TRANSFORM,
            "geometry_msgs/TransformStamped" => TRANSFORM_STAMPED,
            "geometry_msgs/Wrench" => WRENCH,
            "std_msgs/ColorRGBA" => COLOR,
            "nav_msgs/MapMetaData" => MAP_META,
            "visualization_msgs/Marker" => MARKER,
            "std_msgs/MultiArrayLayout" => LAYOUT,
            "std_msgs/MultiArrayDimension" => DIMENSION,
            "geometry_msgs/PoseWithCovariance" => "geometry_msgs/Pose pose\nfloat64[36] covariance\n",
            "geometry_msgs/TwistWithCovariance" => "geometry_msgs/Twist twist\nfloat64[36] covariance\n",
            "geometry_msgs/Twist" => "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n",
            other => unreachable!("no definition for {other}"),
        };
        s.push_str(SEPARATOR);
        s.push_str(&format!("MSG: {d}\n{text}"));
    }
    s
}

const TIME: &str = "int32 sec\nuint32 nanosec\n";
const DURATION: &str = "int32 sec\nuint32 nanosec\n";
const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const POINT: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const VECTOR3: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
const POSE: &str = "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n";
const POSE_STAMPED: &str = "std_msgs/Header header\ngeometry_msgs/Pose pose\n";
const TRANSFORM: &str = "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n";
const TRANSFORM_STAMPED: &str =
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n";
const WRENCH: &str = "geometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n";
const COLOR: &str = "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n";
const MAP_META: &str = "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\ngeometry_msgs/Pose origin\n";
const MARKER: &str = "int32 ARROW=0\nint32 ADD=0\nstd_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring text\nstring mesh_resource\nbool mesh_use_embedded_materials\n";
const LAYOUT: &str = "std_msgs/MultiArrayDimension[] dim\nuint32 data_offset\n";
const DIMENSION: &str = "string label\nuint32 size\nuint32 stride\n";

macro_rules! ros_message {
    ($t:ty, $name:expr, $own:expr, [$($dep:expr),*]) => {
        impl RosMessage for $t {
            const TYPE: &'static str = $name;
            fn definition() -> String {
                with_deps($own, &[$($dep),*])
            }
        }
    };
}

const STAMP_DEPS: [&str; 2] = ["std_msgs/Header", "builtin_interfaces/Time"];
ros_message!(
    PoseStamped,
    "geometry_msgs/msg/PoseStamped",
    POSE_STAMPED,
    [STAMP_DEPS[0], STAMP_DEPS[1], "geometry_msgs/Pose", "geometry_msgs/Point", "geometry_msgs/Quaternion"]
);
ros_message!(
    TransformStamped,
    "geometry_msgs/msg/TransformStamped",
    TRANSFORM_STAMPED,
    [
        STAMP_DEPS[0],
        STAMP_DEPS[1],
        "geometry_msgs/Transform",
        "geometry_msgs/Vector3",
        "geometry_msgs/Quaternion"
    ]
);
ros_message!(
    TfMessage,
    "tf2_msgs/msg/TFMessage",
    "geometry_msgs/TransformStamped[] transforms\n",
    [
        "geometry_msgs/TransformStamped",
        STAMP_DEPS[0],
        STAMP_DEPS[1],
        "geometry_msgs/Transform",
        "geometry_msgs/Vector3",
        "geometry_msgs/Quaternion"
    ]
);
ros_message!(Odometry, "nav_msgs/msg/Odometry", "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n", [STAMP_DEPS[0], STAMP_DEPS[1], "geometry_msgs/PoseWithCovariance", "geometry_msgs/Pose", "geometry_msgs/Point", "geometry_msgs/Quaternion", "geometry_msgs/TwistWithCovariance", "geometry_msgs/Twist", "geometry_msgs/Vector3"]);
ros_message!(
    JointState,
    "sensor_msgs/msg/JointState",
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    [STAMP_DEPS[0], STAMP_DEPS[1]]
);
ros_message!(
    WrenchStamped,
    "geometry_msgs/msg/WrenchStamped",
    "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n",
    [STAMP_DEPS[0], STAMP_DEPS[1], "geometry_msgs/Wrench", "geometry_msgs/Vector3"]
);
ros_message!(
    OccupancyGrid,
    "nav_msgs/msg/OccupancyGrid",
    "std_msgs/Header header\nnav_msgs/MapMetaData info\nint8[] data\n",
    [
        STAMP_DEPS[0],
        STAMP_DEPS[1],
        "nav_msgs/MapMetaData",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion"
    ]
);
ros_message!(
    NavPath,
    "nav_msgs/msg/Path",
    "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
    [
        STAMP_DEPS[0],
        STAMP_DEPS[1],
        "geometry_msgs/PoseStamped",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion"
    ]
);
ros_message!(
    MarkerArray,
    "visualization_msgs/msg/MarkerArray",
    "visualization_msgs/Marker[] markers\n",
    [
        "visualization_msgs/Marker",
        STAMP_DEPS[0],
        STAMP_DEPS[1],
        "builtin_interfaces/Duration",
        "geometry_msgs/Pose",
        "geometry_msgs/Point",
        "geometry_msgs/Quaternion",
        "geometry_msgs/Vector3",
        "std_msgs/ColorRGBA"
    ]
);
ros_message!(StringMsg, "std_msgs/msg/String", "string data\n", []);
ros_message!(
    Float64Array,
    "std_msgs/msg/Float64MultiArray",
    "std_msgs/MultiArrayLayout layout\nfloat64[] data\n",
    ["std_msgs/MultiArrayLayout", "std_msgs/MultiArrayDimension"]
);

/// Why a message's bytes are not the type they should be.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    /// Shorter than the 4-byte encapsulation header.
    #[error("{0} bytes, shorter than CDR's 4-byte encapsulation header")]
    Short(usize),
    /// An encapsulation ROS 2 does not write (only plain CDR, little or big endian).
    #[error("encapsulation {0:#04x} {1:#04x} is not plain CDR (ROS 2 writes 0x00 0x01, little-endian, or 0x00 0x00)")]
    Encapsulation(u8, u8),
    /// The bytes do not decode as the type.
    #[error("does not decode as {0}: {1}")]
    Cdr(&'static str, String),
}

/// Decodes one CDR-encoded message (with its encapsulation header) as `T`.
pub fn decode<T: RosMessage>(data: &[u8]) -> Result<T, DecodeError> {
    if data.len() < 4 {
        return Err(DecodeError::Short(data.len()));
    }
    let body = &data[4..];
    let decoded = match (data[0], data[1]) {
        (0, 1) => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        (0, 0) => cdr_encoding::from_bytes::<T, BigEndian>(body),
        (a, b) => return Err(DecodeError::Encapsulation(a, b)),
    };
    decoded.map(|(v, _)| v).map_err(|e| DecodeError::Cdr(T::TYPE, e.to_string()))
}

/// Encodes a message as CDR little-endian with its encapsulation header (what ROS 2 writes).
pub fn encode<T: RosMessage>(message: &T) -> Vec<u8> {
    let mut out = vec![0u8, 1, 0, 0];
    // Serialising plain structs of numbers, strings and sequences into a vector cannot fail.
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut out, message)
        .expect("CDR encoding of a plain message into memory");
    out
}

/// A position, NaN in every coordinate when one is not finite.
pub(crate) fn point(p: Point) -> [f64; 3] {
    let v = [p.x, p.y, p.z];
    if v.iter().all(|x| x.is_finite()) {
        v
    } else {
        [f64::NAN; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A PoseStamped's bytes laid out by hand from the CDR rules (4-byte header, then
    /// sec, nanosec, the frame's length with its NUL, padding to 8, seven float64).
    #[test]
    fn pose_stamped_bytes_by_hand() {
        let msg = PoseStamped {
            header: Header { stamp: Time { sec: 3, nanosec: 500 }, frame_id: "map".into() },
            pose: Pose { position: Point { x: 1.0, y: 2.0, z: 3.0 }, orientation: Quaternion::default() },
        };
        let bytes = encode(&msg);
        let mut want = vec![0u8, 1, 0, 0];
        want.extend(3i32.to_le_bytes());
        want.extend(500u32.to_le_bytes());
        want.extend(4u32.to_le_bytes());
        want.extend(b"map\0");
        // 16 bytes of body so far: aligned for the float64s.
        for v in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] {
            want.extend(v.to_le_bytes());
        }
        assert_eq!(bytes, want);
        assert_eq!(decode::<PoseStamped>(&bytes).unwrap(), msg);
        assert_eq!(decode::<PoseStamped>(&bytes[..3]), Err(DecodeError::Short(3)));
        let mut odd = bytes.clone();
        odd[1] = 7;
        assert_eq!(decode::<PoseStamped>(&odd), Err(DecodeError::Encapsulation(0, 7)));
        assert!(matches!(decode::<PoseStamped>(&bytes[..30]), Err(DecodeError::Cdr(..))));
    }

    /// A string or sequence declaring 4 GB in a short message is refused, not allocated.
    #[test]
    fn absurd_lengths_are_refused() {
        let mut bytes = vec![0u8, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        bytes.extend(u32::MAX.to_le_bytes());
        assert!(matches!(decode::<JointState>(&bytes), Err(DecodeError::Cdr(..))));
        let mut bytes = encode(&JointState::default());
        let n = bytes.len();
        bytes[n - 16..n - 12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(matches!(decode::<JointState>(&bytes), Err(DecodeError::Cdr(..))));
    }

    #[test]
    fn times_and_type_names() {
        assert_eq!(Time::from_nanos(-1), Time { sec: -1, nanosec: 999_999_999 });
        assert_eq!(Time::from_nanos(2_500_000_000).nanos(), 2_500_000_000);
        assert!(same_type("geometry_msgs/PoseStamped", PoseStamped::TYPE));
        assert!(!same_type("geometry_msgs/msg/Pose", PoseStamped::TYPE));
        assert!(PoseStamped::definition().contains("MSG: geometry_msgs/Quaternion\n"));
    }
}
