//! The device side of Dynamixel Protocol 2.0 (ROBOTIS e-Manual, "Protocol 2.0"): instruction
//! packets parsed from a byte stream, status packets encoded, both with byte stuffing and the
//! CRC-16 of `dynamixel2::checksum` (the client crate's own).
//!
//! Packet: `FF FF FD 00 | ID | LEN_L LEN_H | INST | params... | CRC_L CRC_H`, where LEN counts
//! the instruction (or, in a status packet, the instruction 0x55 and the error byte), the
//! stuffed parameters and the CRC. Inside the parameters every `FF FF FD` is sent as
//! `FF FF FD FD`.

use dynamixel2::checksum::calculate_checksum;

/// The packet header.
pub const HEADER: [u8; 4] = [0xFF, 0xFF, 0xFD, 0x00];
/// Broadcast ID.
pub const BROADCAST: u8 = 0xFE;

/// The Clear instruction's parameters that clear the revolution counter (e-Manual, Protocol
/// 2.0, "Clear").
pub const CLEAR_MULTI_TURN: [u8; 5] = [0x01, 0x44, 0x58, 0x4C, 0x22];

/// Instruction codes.
pub mod inst {
    /// Ping.
    pub const PING: u8 = 0x01;
    /// Read.
    pub const READ: u8 = 0x02;
    /// Write.
    pub const WRITE: u8 = 0x03;
    /// Reboot.
    pub const REBOOT: u8 = 0x08;
    /// Clear (the revolution counter, with the parameters [`super::CLEAR_MULTI_TURN`]).
    pub const CLEAR: u8 = 0x10;
    /// Sync Read.
    pub const SYNC_READ: u8 = 0x82;
    /// Sync Write.
    pub const SYNC_WRITE: u8 = 0x83;
    /// Bulk Read.
    pub const BULK_READ: u8 = 0x92;
    /// Bulk Write.
    pub const BULK_WRITE: u8 = 0x93;
    /// Status (the reply).
    pub const STATUS: u8 = 0x55;
}

/// Status packet error numbers (the low 7 bits of the error byte).
pub mod error {
    /// Result Fail.
    pub const RESULT_FAIL: u8 = 0x01;
    /// Instruction Error.
    pub const INSTRUCTION: u8 = 0x02;
    /// CRC Error.
    pub const CRC: u8 = 0x03;
    /// Data Range Error.
    pub const DATA_RANGE: u8 = 0x04;
    /// Data Length Error.
    pub const DATA_LENGTH: u8 = 0x05;
    /// Data Limit Error.
    pub const DATA_LIMIT: u8 = 0x06;
    /// Access Error (e.g. an EEPROM write while the torque is on).
    pub const ACCESS: u8 = 0x07;
    /// Alert bit: a hardware error is set in Hardware Error Status.
    pub const ALERT: u8 = 0x80;
}

/// One instruction packet, parameters unstuffed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Instruction {
    /// Packet ID.
    pub id: u8,
    /// Instruction code.
    pub instruction: u8,
    /// Parameters.
    pub params: Vec<u8>,
}

/// What the parser found in the stream.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Parsed {
    /// A complete, valid instruction.
    Instruction(Instruction),
    /// A complete packet whose CRC did not match (a servo ignores it).
    BadCrc {
        /// Packet ID.
        id: u8,
    },
}

/// Removes byte stuffing: every `FF FF FD FD` becomes `FF FF FD`.
pub fn unstuff(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len());
    let mut i = 0;
    while i < data.len() {
        out.push(data[i]);
        let n = out.len();
        if n >= 3 && out[n - 3..] == [0xFF, 0xFF, 0xFD] && data.get(i + 1) == Some(&0xFD) {
            i += 1; // skip the stuffed 0xFD
        }
        i += 1;
    }
    out
}

/// Adds byte stuffing: every `FF FF FD` is followed by an extra `FD`.
pub fn stuff(data: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(data.len() + 4);
    for &b in data {
        out.push(b);
        let n = out.len();
        if n >= 3 && out[n - 3..] == [0xFF, 0xFF, 0xFD] {
            out.push(0xFD);
        }
    }
    out
}

/// A complete packet (header to CRC) with `id`, `instruction` and `body` (the bytes after the
/// instruction, before stuffing), stuffed and with its CRC.
pub fn encode(id: u8, instruction: u8, body: &[u8]) -> Vec<u8> {
    let stuffed = stuff(body);
    let len = (stuffed.len() + 3) as u16;
    let mut p = Vec::with_capacity(10 + stuffed.len());
    p.extend_from_slice(&HEADER);
    p.push(id);
    p.extend_from_slice(&len.to_le_bytes());
    p.push(instruction);
    p.extend_from_slice(&stuffed);
    let crc = calculate_checksum(0, &p);
    p.extend_from_slice(&crc.to_le_bytes());
    p
}

/// A status packet from servo `id` with error byte `error` and `params`.
pub fn status(id: u8, error: u8, params: &[u8]) -> Vec<u8> {
    // Stuffing covers the parameters; the error byte is never part of a header pattern.
    let stuffed = stuff(params);
    let len = (stuffed.len() + 4) as u16;
    let mut p = Vec::with_capacity(11 + stuffed.len());
    p.extend_from_slice(&HEADER);
    p.push(id);
    p.extend_from_slice(&len.to_le_bytes());
    p.push(inst::STATUS);
    p.push(error);
    p.extend_from_slice(&stuffed);
    let crc = calculate_checksum(0, &p);
    p.extend_from_slice(&crc.to_le_bytes());
    p
}

/// Longest packet body the parser accepts (a sync write to 252 servos of 4 bytes is 1264).
pub const MAX_LENGTH: usize = 4096;

/// An incremental parser of instruction packets from a byte stream.
#[derive(Debug, Default)]
pub struct Parser {
    buf: Vec<u8>,
}

impl Parser {
    /// Appends received bytes.
    pub fn push(&mut self, bytes: &[u8]) {
        self.buf.extend_from_slice(bytes);
    }

    /// The next complete packet, if any; leading garbage is skipped.
    pub fn next_packet(&mut self) -> Option<Parsed> {
        loop {
            match self.buf.windows(4).position(|w| w == HEADER) {
                Some(start) => {
                    self.buf.drain(..start);
                }
                None => {
                    // Keep a possible partial header at the end; drop everything before it.
                    let n = self.buf.len();
                    let keep =
                        (1..=3).rev().find(|&k| n >= k && self.buf[n - k..] == HEADER[..k]).unwrap_or(0);
                    self.buf.drain(..n - keep);
                    return None;
                }
            }
            if self.buf.len() < 7 {
                return None;
            }
            let len = usize::from(u16::from_le_bytes([self.buf[5], self.buf[6]]));
            if !(3..=MAX_LENGTH).contains(&len) {
                // Not a packet after all: skip this header and look again.
                self.buf.drain(..1);
                continue;
            }
            let total = 7 + len;
            if self.buf.len() < total {
                return None;
            }
            let packet: Vec<u8> = self.buf.drain(..total).collect();
            let id = packet[4];
            let crc = u16::from_le_bytes([packet[total - 2], packet[total - 1]]);
            if calculate_checksum(0, &packet[..total - 2]) != crc {
                return Some(Parsed::BadCrc { id });
            }
            return Some(Parsed::Instruction(Instruction {
                id,
                instruction: packet[7],
                params: unstuff(&packet[8..total - 2]),
            }));
        }
    }
}

/// Where `id` answers in a multi-servo read: its place in the instruction's list.
pub(crate) fn order_of(ins: &Instruction, id: u8) -> usize {
    match ins.instruction {
        inst::SYNC_READ => ins.params.iter().skip(4).position(|&x| x == id).unwrap_or(usize::MAX),
        inst::BULK_READ => ins.params.chunks(5).position(|c| c[0] == id).unwrap_or(usize::MAX),
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stuffing_round_trip_and_by_hand() {
        // e-Manual: FF FF FD in the parameters is sent as FF FF FD FD.
        assert_eq!(stuff(&[1, 0xFF, 0xFF, 0xFD, 2]), vec![1, 0xFF, 0xFF, 0xFD, 0xFD, 2]);
        assert_eq!(unstuff(&[1, 0xFF, 0xFF, 0xFD, 0xFD, 2]), vec![1, 0xFF, 0xFF, 0xFD, 2]);
        let data = [0xFF, 0xFF, 0xFD, 0xFF, 0xFF, 0xFD, 0xFD, 7];
        assert_eq!(unstuff(&stuff(&data)), data.to_vec());
    }

    #[test]
    fn parser_skips_garbage_and_waits_for_whole_packets() {
        // e-Manual's ping of ID 1: FF FF FD 00 01 03 00 01 19 4E.
        let ping = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E];
        let mut p = Parser::default();
        p.push(&[0x00, 0x12, 0xFF]);
        p.push(&ping[1..6]);
        assert_eq!(p.next_packet(), None);
        p.push(&ping[6..]);
        assert_eq!(
            p.next_packet(),
            Some(Parsed::Instruction(Instruction { id: 1, instruction: inst::PING, params: vec![] }))
        );
        // The same packet with its CRC's last byte flipped.
        let mut bad = ping;
        bad[9] ^= 0xFF;
        p.push(&bad);
        assert_eq!(p.next_packet(), Some(Parsed::BadCrc { id: 1 }));
        assert_eq!(p.next_packet(), None);
    }
}
