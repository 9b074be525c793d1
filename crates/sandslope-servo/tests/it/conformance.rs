//! Protocol 2.0 conformance of the emulator: against packets written out by hand from the
//! ROBOTIS e-Manual's Protocol 2.0 examples, and against the `dynamixel2` crate's own packet
//! encoder and CRC talking to it over a pseudo-terminal.

use sandslope::{Robot, RobotSpec, Terrain};
use sandslope_servo::emulator::VirtualBus;
use sandslope_servo::packet::{self, Parsed, Parser};
use sandslope_servo::table as t;
use sandslope_servo::{Emulator, EmulatorConfig, ServoConfig};

fn config(model: u16, firmware: u8, positions: &[i32]) -> EmulatorConfig {
    let servos = positions
        .iter()
        .enumerate()
        .map(|(i, &p)| ServoConfig { id: i as u8 + 1, direction: 1, zero_offset_pulses: p })
        .collect();
    let robot = Robot::new(RobotSpec::paper_hexapod()).unwrap();
    let mut c = EmulatorConfig::new(robot, Terrain::constant(7e5, 2e6).unwrap(), 10.0, servos);
    c.model_number = model;
    c.firmware = firmware;
    c.current_noise_ma = 0.0;
    c.simulated_strides = 3;
    c
}

fn exchange(bus: &mut VirtualBus, bytes: &[u8]) -> Vec<u8> {
    let mut p = Parser::default();
    p.push(bytes);
    let mut out = vec![];
    while let Some(packet) = p.next_packet() {
        out.extend(bus.respond(packet, 0.0));
    }
    out
}

/// The e-Manual's examples use two XM430-W210s (model 1030, firmware 38) at present positions
/// 166 and 2079; the emulator is set up so (a shaft at rest with the torque off stays at its
/// zero offset).
#[test]
fn hand_written_packets_from_the_protocol_documentation() {
    let mut bus = VirtualBus::new(&config(1030, 38, &[166, 2079])).unwrap();
    // Ping, ID 1.
    let reply = exchange(&mut bus, &[0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4E]);
    assert_eq!(reply, [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D]);
    // Ping, broadcast: both answer, ID 1 first.
    let reply = exchange(&mut bus, &[0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x03, 0x00, 0x01, 0x31, 0x42]);
    assert_eq!(
        &reply[..14],
        [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x07, 0x00, 0x55, 0x00, 0x06, 0x04, 0x26, 0x65, 0x5D]
    );
    assert_eq!(reply[4 + 14], 0x02);
    // Sync Read of Present Position (132, 4 bytes) from IDs 1 and 2.
    let reply = exchange(
        &mut bus,
        &[0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA],
    );
    let id1 = [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x08, 0x00, 0x55, 0x00, 0xA6, 0x00, 0x00, 0x00, 0x8C, 0xC0];
    let id2 = [0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x08, 0x00, 0x55, 0x00, 0x1F, 0x08, 0x00, 0x00, 0xBA, 0xBE];
    assert_eq!(reply, [&id1[..], &id2[..]].concat());
    // Sync Write of Goal Position (116): 150 to ID 1, 170 to ID 2; no reply.
    let reply = exchange(
        &mut bus,
        &[
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x11, 0x00, 0x83, 0x74, 0x00, 0x04, 0x00, 0x01, 0x96, 0x00, 0x00,
            0x00, 0x02, 0xAA, 0x00, 0x00, 0x00, 0x82, 0x87,
        ],
    );
    assert!(reply.is_empty());
    // Read back with the emulator's own encoder: Goal Position of ID 2 is 170.
    let reply = exchange(&mut bus, &packet::encode(2, packet::inst::READ, &[0x74, 0x00, 0x04, 0x00]));
    assert_eq!(&reply[9..13], &170u32.to_le_bytes());
    // A status packet without parameters from ID 1 is FF FF FD 00 01 04 00 55 00 A1 0C (the
    // e-Manual's reply to its Write, Reg Write and Action examples).
    let reply = exchange(&mut bus, &packet::encode(1, packet::inst::WRITE, &[0x41, 0x00, 0x01]));
    assert_eq!(reply, [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x04, 0x00, 0x55, 0x00, 0xA1, 0x0C]);
    // Bulk Read: Present Input Voltage (144, 2 bytes) of ID 1, Present Temperature (146, 1
    // byte) of ID 2. The values differ from the e-Manual's (the emulator's own), so the
    // replies are checked field by field, their CRCs by the parser's.
    let reply = exchange(
        &mut bus,
        &[
            0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x0D, 0x00, 0x92, 0x01, 0x90, 0x00, 0x02, 0x00, 0x02, 0x92, 0x00,
            0x01, 0x00, 0x1A, 0x05,
        ],
    );
    assert_eq!(&reply[..9], [0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x06, 0x00, 0x55, 0x00]);
    assert_eq!(&reply[13..22], [0xFF, 0xFF, 0xFD, 0x00, 0x02, 0x05, 0x00, 0x55, 0x00]);
    assert_eq!(reply.len(), 13 + 12);
    let crc = |p: &[u8]| dynamixel2::checksum::calculate_checksum(0, &p[..p.len() - 2]).to_le_bytes();
    assert_eq!(crc(&reply[..13]), [reply[11], reply[12]]);
    assert_eq!(crc(&reply[13..]), [reply[23], reply[24]]);
    // A packet whose CRC is wrong is ignored, as a servo does.
    let reply = exchange(&mut bus, &[0xFF, 0xFF, 0xFD, 0x00, 0x01, 0x03, 0x00, 0x01, 0x19, 0x4F]);
    assert!(reply.is_empty());
    assert_eq!(bus.report().bad_crc, 1);
    // The EEPROM area cannot be written with the torque on: Access Error (0x07).
    exchange(&mut bus, &packet::encode(1, packet::inst::WRITE, &[64, 0, 1]));
    let reply = exchange(&mut bus, &packet::encode(1, packet::inst::WRITE, &[11, 0, 1]));
    assert_eq!(reply[8], 0x07);
    // The parser hands back the instruction as written.
    let mut p = Parser::default();
    p.push(&[0xFF, 0xFF, 0xFD, 0x00, 0xFE, 0x09, 0x00, 0x82, 0x84, 0x00, 0x04, 0x00, 0x01, 0x02, 0xCE, 0xFA]);
    match p.next_packet() {
        Some(Parsed::Instruction(i)) => {
            assert_eq!(
                (i.id, i.instruction, i.params),
                (0xFE, 0x82, vec![0x84, 0x00, 0x04, 0x00, 0x01, 0x02])
            )
        }
        other => panic!("{other:?}"),
    }
}

/// The `dynamixel2` client over a pty: its encoder and CRC against the emulator's, every
/// instruction the driver uses.
#[test]
fn the_dynamixel2_client_talks_to_the_emulator_over_a_pty() {
    let cfg =
        config(sandslope::servo::ServoModel::XL330_M288.model_number, 46, &[100, 200, 300, 400, 500, 600]);
    let (emulator, port) = Emulator::start(&cfg).unwrap();
    let mut bus = dynamixel2::Bus::new(port).unwrap();
    let ping = bus.ping(3).unwrap();
    assert_eq!((ping.motor_id, ping.data.model, ping.data.firmware), (3, 1200, 46));
    let mut found: Vec<u8> = bus.scan().unwrap().into_iter().map(|r| r.unwrap().motor_id).collect();
    found.sort_unstable();
    assert_eq!(found, vec![1, 2, 3, 4, 5, 6]);
    assert!(bus.ping(9).is_err(), "no servo 9");
    // Read and write.
    assert_eq!(bus.read_u32(2, t::PRESENT_POSITION).unwrap().data, 200);
    bus.write_u16(2, t::CURRENT_LIMIT, 900).unwrap();
    assert_eq!(bus.read_u16(2, t::CURRENT_LIMIT).unwrap().data, 900);
    // Sync write and sync read.
    let data: Vec<_> = (1..=6u8)
        .map(|id| dynamixel2::instructions::SyncWriteData {
            motor_id: id,
            data: (1000 + u32::from(id)).to_le_bytes(),
        })
        .collect();
    bus.sync_write(t::PROFILE_VELOCITY, 4, &data).unwrap();
    let back = bus.sync_read_u32(&[6, 1, 4], t::PROFILE_VELOCITY).unwrap();
    assert_eq!(
        back.iter().map(|r| (r.motor_id, r.data)).collect::<Vec<_>>(),
        vec![(6, 1006), (1, 1001), (4, 1004)]
    );
    // Bulk read. dynamixel2 0.9.1 writes the k-th entry at parameter offset k instead of 5 k
    // (instructions/bulk_read.rs: `&mut buffer[i..][..5]`), so only a one-servo Bulk Read is
    // well formed; the driver uses Sync Read, and the e-Manual's two-servo Bulk Read is
    // checked by hand in the test above.
    let reads =
        [dynamixel2::instructions::BulkReadData { motor_id: 5, address: t::TEMPERATURE_LIMIT, count: 1 }];
    let got = bus.bulk_read(&reads).unwrap();
    assert_eq!((got[0].motor_id, got[0].data.clone()), (5, vec![70]));
    // A parameter that needs byte stuffing: FF FF FD written into a 4-byte register (Goal
    // Position -131,073 pulses, within the extended position mode's range).
    bus.write_u8(1, t::OPERATING_MODE, 4).unwrap();
    bus.write_u32(1, t::GOAL_POSITION, u32::from_le_bytes([0xFF, 0xFF, 0xFD, 0xFF])).unwrap();
    assert_eq!(bus.read(1, t::GOAL_POSITION, 4).unwrap().data, vec![0xFF, 0xFF, 0xFD, 0xFF]);
    // The e-Manual's ranges, answered with a Data Range Error (4) and nothing written:
    // Goal Position beyond 1,048,575 in extended position mode, Goal Velocity above the
    // Velocity Limit (445 by default), Current Limit above 1750 mA.
    let range_error = |r: Result<dynamixel2::Response<()>, dynamixel2::TransferError>| match r {
        Err(dynamixel2::TransferError::ReadError(dynamixel2::ReadError::MotorError(e))) => e.error_number(),
        other => panic!("expected a Data Range Error, got {other:?}"),
    };
    assert_eq!(range_error(bus.write_u32(1, t::GOAL_POSITION, 1_048_576)), 4);
    assert_eq!(range_error(bus.write_u32(1, t::GOAL_POSITION, (-1_048_576i32) as u32)), 4);
    assert!(bus.write_u32(1, t::GOAL_POSITION, 1_048_575).is_ok());
    assert_eq!(bus.read_u32(1, t::GOAL_POSITION).unwrap().data, 1_048_575);
    assert_eq!(range_error(bus.write_u32(1, t::GOAL_VELOCITY, 446)), 4);
    assert!(bus.write_u32(1, t::GOAL_VELOCITY, 445).is_ok());
    assert_eq!(range_error(bus.write_u16(1, t::CURRENT_LIMIT, 1751)), 4);
    assert_eq!(bus.read_u16(1, t::CURRENT_LIMIT).unwrap().data, 1750);
    assert_eq!(range_error(bus.write_u8(1, t::OPERATING_MODE, 2)), 4);
    // The Clear instruction brings the revolution counter back within one turn.
    assert!(bus.clear_revolution_counter(1).is_ok());
    drop(bus);
    let report = emulator.stop(None);
    assert_eq!(report.bad_crc, 0);
    assert!(report.packets >= 10);
}

/// The Bus Watchdog (98, 20 ms units): a servo with the torque on that hears nothing for
/// longer stops and sets it to 100 (e-Manual, Bus Watchdog).
#[test]
fn the_bus_watchdog_fires_on_a_quiet_bus() {
    let mut bus = VirtualBus::new(&config(1200, 46, &[0])).unwrap();
    let write = |addr: u8, v: u8| packet::encode(1, packet::inst::WRITE, &[addr, 0, v]);
    let mut p = Parser::default();
    p.push(&write(t::BUS_WATCHDOG as u8, 5));
    p.push(&write(t::TORQUE_ENABLE as u8, 1));
    while let Some(x) = p.next_packet() {
        bus.respond(x, 0.0);
    }
    bus.tick(0.09);
    assert_eq!(bus.report().watchdog, vec![(1, 5)], "0.09 s of silence is within 5 x 20 ms");
    bus.tick(0.11);
    assert_eq!(bus.report().watchdog, vec![(1, 100)]);
}
