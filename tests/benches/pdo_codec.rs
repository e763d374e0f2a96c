//! Decodes and encodes every default PDO of the three seed devices with the
//! generated code of `eds2rust-drivers`, with hand-written shift code for the
//! same PDOs, and (in the same run) with python-canopen 2.4.1's PDO maps;
//! prints ns per frame and the ratios.
//!
//! `cargo bench -p eds2rust-tests --bench pdo_codec`
//!
//! Rows: `decode` is bytes (a slice whose length the compiler does not know)
//! → the struct, handed on (`black_box`) when the frame is valid; python-canopen's decode is
//! `map.on_message(...)` and `.raw` of every mapped variable. `encode` is the
//! struct → bytes; python-canopen's sets `.raw` of every mapped variable and
//! takes `bytes(map.data)`. Before timing, every frame must decode to the same
//! values through the generated and the hand-written code (the raw value of
//! every mapped field, every named bit and bit field), python-canopen must
//! read the same raw values, all three must encode them back to the frame,
//! and frames one byte short or long (and empty) must be rejected.
//!
//! The timing loops run 16 frames per step, unrolled. At about two cycles a
//! frame, a one-frame loop times where the linker puts it as much as what
//! it runs: the same instructions at two addresses timed up to 1.3x apart.

use std::hint::black_box;
use std::time::Instant;

use eds2rust_drivers::{interroll_ec5000bi as ir, linak_techline as lk, zimmer_acs as zm};
use eds2rust_runtime::od::Pdo;
use serde_json::{Value as Json, json};

/// A CAN frame's data: up to 8 bytes.
#[derive(Clone, Copy)]
struct Frame {
    data: [u8; 8],
    len: usize,
}

impl Frame {
    fn new(bytes: &[u8]) -> Frame {
        let mut data = [0; 8];
        data[..bytes.len()].copy_from_slice(bytes);
        let len = bytes.len();
        Frame { data, len }
    }
    fn bytes(&self) -> &[u8] {
        &self.data[..self.len]
    }
}

/// `count` deterministic pseudo-random frames of `len` bytes (xorshift64*).
fn random_frames(seed: u64, len: usize, count: usize) -> Vec<Frame> {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..count)
        .map(|_| {
            state ^= state >> 12;
            state ^= state << 25;
            state ^= state >> 27;
            let bytes = state.wrapping_mul(0x2545_F491_4F6C_DD1D).to_le_bytes();
            Frame::new(&bytes[..len])
        })
        .collect()
}

fn hex_frames(frames: &[&str]) -> Vec<Frame> {
    let byte = |b: &str| u8::from_str_radix(b, 16).expect("hex byte");
    let frame = |f: &&str| Frame::new(&f.split(' ').map(byte).collect::<Vec<u8>>());
    frames.iter().map(frame).collect()
}

/// What an integrator writes today: fixed byte offsets, `from_le_bytes`, a
/// plain struct of raw integer fields; the bits are read with `>> bit & 1`
/// at the bit positions of the manuals (the `*_BITS` tables).
#[rustfmt::skip]
mod hand {
    pub const LK_STATUS_BITS: [u8; 8] = [0, 1, 2, 3, 4, 5, 6, 7];
    pub const LK_PARALLEL_BITS: [u8; 3] = [0, 1, 2];
    pub const ZM_STATUS_BITS: [u8; 13] = [0, 1, 2, 3, 4, 5, 6, 7, 10, 11, 12, 13, 14];
    pub const ZM_CONTROL_BITS: [u8; 9] = [0, 1, 2, 3, 4, 5, 6, 7, 8];
    pub const IR_STATUS_BITS: [u8; 16] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15];
    pub const IR_CONTROL_BITS: [u8; 15] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 11, 12, 13, 14, 15];
    pub const IR_ERROR_REGISTER_BITS: [u8; 7] = [0, 1, 2, 3, 4, 5, 7];

    #[inline] fn u16_at(d: &[u8], i: usize) -> u16 { u16::from_le_bytes([d[i], d[i + 1]]) }
    #[inline] fn i16_at(d: &[u8], i: usize) -> i16 { i16::from_le_bytes([d[i], d[i + 1]]) }
    #[inline] fn i32_at(d: &[u8], i: usize) -> i32 { i32::from_le_bytes([d[i], d[i + 1], d[i + 2], d[i + 3]]) }

    /// LINAK TPDO1: position, current, status flags, error code, speed, AUX inputs.
    #[derive(Clone, Copy)]
    pub struct LkFeedback { pub position: u16, pub current: u8, pub status: u8, pub error_code: u8, pub speed: u16, pub aux: u8 }
    impl LkFeedback {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 8 { return None; }
            Some(Self { position: u16_at(d, 0), current: d[2], status: d[3], error_code: d[4], speed: u16_at(d, 5), aux: d[7] })
        }
        #[inline] pub fn encode(&self) -> [u8; 8] {
            let ([p0, p1], [s0, s1]) = (self.position.to_le_bytes(), self.speed.to_le_bytes());
            [p0, p1, self.current, self.status, self.error_code, s0, s1, self.aux]
        }
        /// AUX input `n` (1..=4): 2 bits each, 0-3 = 0-25-50-75 % VCC.
        #[inline] pub fn aux_level(&self, n: u8) -> u8 { (self.aux >> (2 * (n - 1))) & 0x3 }
    }

    /// LINAK RPDO1: position, current limit, speed, soft start, soft stop, 2 reserved bytes.
    #[derive(Clone, Copy)]
    pub struct LkCommand { pub position: u16, pub current_limit: u8, pub speed: u8, pub soft_start: u8, pub soft_stop: u8, pub reserved: [u8; 2] }
    impl LkCommand {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 8 { return None; }
            Some(Self { position: u16_at(d, 0), current_limit: d[2], speed: d[3], soft_start: d[4], soft_stop: d[5], reserved: [d[6], d[7]] })
        }
        #[inline] pub fn encode(&self) -> [u8; 8] {
            let [p0, p1] = self.position.to_le_bytes();
            [p0, p1, self.current_limit, self.speed, self.soft_start, self.soft_stop, self.reserved[0], self.reserved[1]]
        }
    }

    /// LINAK TPDO2: parallel error source, error code, status flags, 5 reserved bytes.
    #[derive(Clone, Copy)]
    pub struct LkParallel { pub error_source: u8, pub error_code: u8, pub status: u8, pub reserved: [u8; 5] }
    impl LkParallel {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 8 { return None; }
            Some(Self { error_source: d[0], error_code: d[1], status: d[2], reserved: [d[3], d[4], d[5], d[6], d[7]] })
        }
        #[inline] pub fn encode(&self) -> [u8; 8] {
            let r = self.reserved;
            [self.error_source, self.error_code, self.status, r[0], r[1], r[2], r[3], r[4]]
        }
    }

    /// A CiA 402 control or status word and a `SIGNED32` (target or actual value).
    #[derive(Clone, Copy)]
    pub struct WordAnd32 { pub word: u16, pub value: i32 }
    impl WordAnd32 {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 6 { return None; }
            Some(Self { word: u16_at(d, 0), value: i32_at(d, 2) })
        }
        #[inline] pub fn encode(&self) -> [u8; 6] {
            let ([w0, w1], [v0, v1, v2, v3]) = (self.word.to_le_bytes(), self.value.to_le_bytes());
            [w0, w1, v0, v1, v2, v3]
        }
    }

    /// One 32-bit value: `UNSIGNED32` (Zimmer RPDO2) or `SIGNED32` (TPDO2, read `as i32`).
    #[derive(Clone, Copy)]
    pub struct One32 { pub value: u32 }
    impl One32 {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> { Some(Self { value: u32::from_le_bytes(d.try_into().ok()?) }) }
        #[inline] pub fn encode(&self) -> [u8; 4] { self.value.to_le_bytes() }
    }

    /// Zimmer TPDO3: following error (`SIGNED32`), torque (`SIGNED16`).
    #[derive(Clone, Copy)]
    pub struct ZmFollowingTorque { pub following_error: i32, pub torque: i16 }
    impl ZmFollowingTorque {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 6 { return None; }
            Some(Self { following_error: i32_at(d, 0), torque: i16_at(d, 4) })
        }
        #[inline] pub fn encode(&self) -> [u8; 6] {
            let ([f0, f1, f2, f3], [t0, t1]) = (self.following_error.to_le_bytes(), self.torque.to_le_bytes());
            [f0, f1, f2, f3, t0, t1]
        }
    }

    /// Interroll RPDO1: controlword, mode of operation (`INTEGER8`), profile velocity (`UNSIGNED32`).
    #[derive(Clone, Copy)]
    pub struct IrVelocityCommand { pub controlword: u16, pub mode: i8, pub profile_velocity: u32 }
    impl IrVelocityCommand {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 7 { return None; }
            Some(Self { controlword: u16_at(d, 0), mode: d[2] as i8, profile_velocity: u32::from_le_bytes([d[3], d[4], d[5], d[6]]) })
        }
        #[inline] pub fn encode(&self) -> [u8; 7] {
            let ([c0, c1], [v0, v1, v2, v3]) = (self.controlword.to_le_bytes(), self.profile_velocity.to_le_bytes());
            [c0, c1, self.mode as u8, v0, v1, v2, v3]
        }
    }

    /// Interroll TPDO1: statusword, mode display (`INTEGER8`), error register, temperature, torque.
    #[derive(Clone, Copy)]
    pub struct IrStatus { pub statusword: u16, pub mode_display: i8, pub error_register: u8, pub temperature: i16, pub torque: i16 }
    impl IrStatus {
        #[inline] pub fn decode(d: &[u8]) -> Option<Self> {
            if d.len() != 8 { return None; }
            Some(Self { statusword: u16_at(d, 0), mode_display: d[2] as i8, error_register: d[3], temperature: i16_at(d, 4), torque: i16_at(d, 6) })
        }
        #[inline] pub fn encode(&self) -> [u8; 8] {
            let [s0, s1] = self.statusword.to_le_bytes();
            let ([t0, t1], [q0, q1]) = (self.temperature.to_le_bytes(), self.torque.to_le_bytes());
            [s0, s1, self.mode_display as u8, self.error_register, t0, t1, q0, q1]
        }
    }
}

/// The values both sides must agree on, per decoded PDO: the raw value of
/// every mapped field in mapping order, then every named bit (0/1) and bit field.
#[rustfmt::skip]
mod values {
    use super::{hand, ir, lk, zm};

    /// `head`, then `bits` as 0/1, as one array.
    fn join<const K: usize>(head: &[i64], bits: &[bool]) -> [i64; K] {
        let mut v = [0; K];
        v[..head.len()].copy_from_slice(head);
        v[head.len()..].iter_mut().zip(bits).for_each(|(o, &b)| *o = i64::from(b));
        v
    }
    /// `head`, then the bits of `raw` at `positions` (the hand-written bit tests).
    fn join_bits<const K: usize>(head: &[i64], raw: u64, positions: &[u8]) -> [i64; K] {
        let mut v = [0; K];
        v[..head.len()].copy_from_slice(head);
        v[head.len()..].iter_mut().zip(positions).for_each(|(o, &p)| *o = (raw >> p & 1) as i64);
        v
    }

    fn lk_status(s: lk::od::feedback::StatusFlagsValue) -> [bool; 8] {
        [s.end_stop_in(), s.end_stop_out(), s.overcurrent(), s.running_out(), s.running_in(),
         s.heartbeat_required(), s.outside_nominal_conditions(), s.always_set()]
    }
    fn zm_status(s: zm::od::StatuswordValue) -> [bool; 13] {
        [s.ready_to_switch_on(), s.switched_on(), s.operation_enabled(), s.fault(), s.voltage_enabled(),
         s.quick_stop(), s.switch_on_disabled(), s.warning(), s.target_reached(), s.internal_limit_active(),
         s.setpoint_ack(), s.following_error(), s.initial_angle_determination_finished()]
    }
    fn zm_control(c: zm::od::ControlwordValue) -> [bool; 9] {
        [c.switch_on(), c.enable_voltage(), c.quick_stop(), c.enable_operation(), c.latch_setpoint(),
         c.change_immediately(), c.abs_rel(), c.fault_reset(), c.halt()]
    }
    fn ir_status(s: ir::od::StatuswordValue) -> [bool; 16] {
        [s.ready_to_switch_on(), s.switched_on(), s.operation_enabled(), s.fault(), s.voltage_enabled(),
         s.quick_stop(), s.switch_on_disabled(), s.warning(), s.manufacturer_specific_error_bit(), s.remote(),
         s.target_reached(), s.internal_limit_active(), s.set_point_acknowledge(), s.following_error(),
         s.manufacturer_specific_14(), s.manufacturer_specific_15()]
    }
    fn ir_control(c: ir::od::ControlwordValue) -> [bool; 15] {
        [c.switch_on(), c.enable_voltage(), c.quick_stop(), c.enable_operation(), c.new_set_point(),
         c.change_set_immediately(), c.absolute_relative(), c.fault_reset(), c.halt(), c.change_of_set_point(),
         c.manufacturer_specific_11(), c.manufacturer_specific_12(), c.manufacturer_specific_13(),
         c.manufacturer_specific_14(), c.manufacturer_specific_15()]
    }
    fn ir_error_register(e: ir::od::ErrorRegisterValue) -> [bool; 7] {
        [e.generic_error(), e.current(), e.voltage(), e.temperature(), e.communication_error(),
         e.device_profile_specific(), e.manufacturer_specific()]
    }

    pub fn lk_tpdo1(f: &lk::pdo::Tpdo1Feedback) -> [i64; 18] {
        let (s, a) = (f.status_flags, f.aux_inputs);
        let head = [f.position.to_raw(), f.current.to_raw().into(), s.to_raw().into(), f.error_code.to_raw().into(),
                    f.speed.to_raw(), a.to_raw().into()];
        let mut v: [i64; 18] = join(&head.map(i64::from), &lk_status(s));
        let levels = [a.input_level_1(), a.input_level_2(), a.input_level_3(), a.input_level_4()];
        v[14..].copy_from_slice(&levels.map(i64::from));
        v
    }
    pub fn hand_lk_tpdo1(f: &hand::LkFeedback) -> [i64; 18] {
        let head = [f.position, f.current.into(), f.status.into(), f.error_code.into(), f.speed, f.aux.into()];
        let mut v: [i64; 18] = join_bits(&head.map(i64::from), f.status.into(), &hand::LK_STATUS_BITS);
        v[14..].copy_from_slice(&[1, 2, 3, 4].map(|n| i64::from(f.aux_level(n))));
        v
    }
    pub fn lk_rpdo1(c: &lk::pdo::Rpdo1Command) -> [i64; 7] {
        [c.position.to_raw(), c.current_limit.to_raw().into(), c.speed.to_raw().into(), c.soft_start.to_raw().into(),
         c.soft_stop.to_raw().into(), c.reserved_6.into(), c.reserved_7.into()].map(i64::from)
    }
    pub fn hand_lk_rpdo1(c: &hand::LkCommand) -> [i64; 7] {
        [c.position, c.current_limit.into(), c.speed.into(), c.soft_start.into(), c.soft_stop.into(),
         c.reserved[0].into(), c.reserved[1].into()].map(i64::from)
    }
    pub fn lk_tpdo2(p: &lk::pdo::Tpdo2ParallelFeedback) -> [i64; 11] {
        let s = p.parallel_status_flags;
        let head = [p.parallel_error_source.to_raw(), p.parallel_error_code.to_raw(), s.to_raw(), p.reserved_4,
                    p.reserved_5, p.reserved_6, p.reserved_7, p.reserved_8];
        join(&head.map(i64::from), &[s.parallel_end_stop_out(), s.parallel_end_stop_in(), s.outside_nominal_conditions()])
    }
    pub fn hand_lk_tpdo2(p: &hand::LkParallel) -> [i64; 11] {
        let r = p.reserved;
        let head = [p.error_source, p.error_code, p.status, r[0], r[1], r[2], r[3], r[4]];
        join_bits(&head.map(i64::from), p.status.into(), &hand::LK_PARALLEL_BITS)
    }
    pub fn zm_rpdo1(r: &zm::pdo::Rpdo1ControlAndTargetPosition) -> [i64; 11] {
        let c = r.controlword;
        join(&[c.to_raw().into(), r.target_position.to_raw().into()], &zm_control(c))
    }
    pub fn hand_zm_rpdo1(r: &hand::WordAnd32) -> [i64; 11] {
        join_bits(&[r.word.into(), r.value.into()], r.word.into(), &hand::ZM_CONTROL_BITS)
    }
    pub fn zm_rpdo2(r: &zm::pdo::Rpdo2ProfileVelocity) -> [i64; 1] { [r.profile_velocity.to_raw().into()] }
    pub fn hand_u32(r: &hand::One32) -> [i64; 1] { [r.value.into()] }
    pub fn zm_tpdo1(t: &zm::pdo::Tpdo1StatusAndPosition) -> [i64; 15] {
        let s = t.statusword;
        join(&[s.to_raw().into(), t.position_actual_value.to_raw().into()], &zm_status(s))
    }
    pub fn hand_zm_tpdo1(t: &hand::WordAnd32) -> [i64; 15] {
        join_bits(&[t.word.into(), t.value.into()], t.word.into(), &hand::ZM_STATUS_BITS)
    }
    pub fn zm_tpdo2(t: &zm::pdo::Tpdo2Velocity) -> [i64; 1] { [t.velocity_actual_value.to_raw().into()] }
    pub fn hand_i32(t: &hand::One32) -> [i64; 1] { [(t.value as i32).into()] }
    pub fn zm_tpdo3(t: &zm::pdo::Tpdo3FollowingErrorAndTorque) -> [i64; 2] {
        [t.following_error_actual_value.to_raw().into(), t.torque_actual_value.to_raw().into()]
    }
    pub fn hand_zm_tpdo3(t: &hand::ZmFollowingTorque) -> [i64; 2] { [t.following_error.into(), t.torque.into()] }
    pub fn ir_rpdo1(r: &ir::pdo::Rpdo1VelocityCommand) -> [i64; 18] {
        let c = r.controlword;
        let head = [c.to_raw().into(), r.modes_of_operation.to_raw().into(), r.profile_velocity.to_raw().into()];
        join(&head, &ir_control(c))
    }
    pub fn hand_ir_rpdo1(r: &hand::IrVelocityCommand) -> [i64; 18] {
        let head = [r.controlword.into(), r.mode.into(), r.profile_velocity.into()];
        join_bits(&head, r.controlword.into(), &hand::IR_CONTROL_BITS)
    }
    pub fn ir_rpdo2(r: &ir::pdo::Rpdo2PositionCommand) -> [i64; 17] {
        join(&[r.controlword.to_raw().into(), r.target_position.to_raw().into()], &ir_control(r.controlword))
    }
    pub fn ir_rpdo3(r: &ir::pdo::Rpdo3TargetVelocityCommand) -> [i64; 17] {
        join(&[r.controlword.to_raw().into(), r.target_velocity.to_raw().into()], &ir_control(r.controlword))
    }
    pub fn hand_ir_rpdo23(r: &hand::WordAnd32) -> [i64; 17] {
        join_bits(&[r.word.into(), r.value.into()], r.word.into(), &hand::IR_CONTROL_BITS)
    }
    pub fn ir_tpdo1(t: &ir::pdo::Tpdo1Status) -> [i64; 28] {
        let (s, e) = (t.statusword, t.error_register);
        let head = [s.to_raw().into(), t.modes_of_operation_display.to_raw().into(), e.to_raw().into(),
                    t.actual_temperature.to_raw().into(), t.torque_actual_value.to_raw().into()];
        let mut v: [i64; 28] = join(&head, &ir_status(s));
        v[21..].copy_from_slice(&ir_error_register(e).map(i64::from));
        v
    }
    pub fn hand_ir_tpdo1(t: &hand::IrStatus) -> [i64; 28] {
        let head = [t.statusword.into(), t.mode_display.into(), t.error_register.into(), t.temperature.into(), t.torque.into()];
        let mut v: [i64; 28] = join_bits(&head, t.statusword.into(), &hand::IR_STATUS_BITS);
        let er = u64::from(t.error_register);
        v[21..].iter_mut().zip(hand::IR_ERROR_REGISTER_BITS).for_each(|(o, p)| *o = (er >> p & 1) as i64);
        v
    }
    pub fn ir_tpdo2(t: &ir::pdo::Tpdo2Position) -> [i64; 18] {
        join(&[t.statusword.to_raw().into(), t.position_actual_value.to_raw().into()], &ir_status(t.statusword))
    }
    pub fn ir_tpdo3(t: &ir::pdo::Tpdo3Velocity) -> [i64; 18] {
        join(&[t.statusword.to_raw().into(), t.velocity_actual_value.to_raw().into()], &ir_status(t.statusword))
    }
    pub fn hand_ir_tpdo23(t: &hand::WordAnd32) -> [i64; 18] {
        join_bits(&[t.word.into(), t.value.into()], t.word.into(), &hand::IR_STATUS_BITS)
    }
}

/// The seed devices' default PDOs again, declared with `#[derive(Pdo)]`:
/// the same mappings and field types as the generated structs.
#[rustfmt::skip]
mod derived {
    use eds2rust_drivers::{interroll_ec5000bi as ir, linak_techline as lk, zimmer_acs as zm};
    use eds2rust_runtime::Pdo;
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 1)]
    pub struct LkRpdo1Command {
        #[pdo(entry = lk::od::command::Position)] pub position: lk::od::command::PositionValue,
        #[pdo(entry = lk::od::command::CurrentLimit)] pub current_limit: lk::od::command::CurrentLimitValue,
        #[pdo(entry = lk::od::command::Speed)] pub speed: lk::od::command::SpeedValue,
        #[pdo(entry = lk::od::command::SoftStart)] pub soft_start: lk::od::command::SoftStartValue,
        #[pdo(entry = lk::od::command::SoftStop)] pub soft_stop: lk::od::command::SoftStopValue,
        #[pdo(entry = lk::od::command::Reserved6)] pub reserved_6: u8,
        #[pdo(entry = lk::od::command::Reserved7)] pub reserved_7: u8,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 1)]
    pub struct LkTpdo1Feedback {
        #[pdo(entry = lk::od::feedback::Position)] pub position: lk::od::feedback::PositionValue,
        #[pdo(entry = lk::od::feedback::Current)] pub current: lk::od::feedback::CurrentValue,
        #[pdo(entry = lk::od::feedback::StatusFlags)] pub status_flags: lk::od::feedback::StatusFlagsValue,
        #[pdo(entry = lk::od::feedback::ErrorCode)] pub error_code: lk::errors::LinakErrorsCode,
        #[pdo(entry = lk::od::feedback::Speed)] pub speed: lk::od::feedback::SpeedValue,
        #[pdo(entry = lk::od::feedback::AuxInputs)] pub aux_inputs: lk::od::feedback::AuxInputsValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct LkTpdo2ParallelFeedback {
        #[pdo(entry = lk::od::parallel_feedback::ParallelErrorSource)] pub parallel_error_source: lk::od::parallel_feedback::ParallelErrorSourceValue,
        #[pdo(entry = lk::od::parallel_feedback::ParallelErrorCode)] pub parallel_error_code: lk::errors::ParallelErrorsCode,
        #[pdo(entry = lk::od::parallel_feedback::ParallelStatusFlags)] pub parallel_status_flags: lk::od::parallel_feedback::ParallelStatusFlagsValue,
        #[pdo(entry = lk::od::parallel_feedback::Reserved4)] pub reserved_4: u8,
        #[pdo(entry = lk::od::parallel_feedback::Reserved5)] pub reserved_5: u8,
        #[pdo(entry = lk::od::parallel_feedback::Reserved6)] pub reserved_6: u8,
        #[pdo(entry = lk::od::parallel_feedback::Reserved7)] pub reserved_7: u8,
        #[pdo(entry = lk::od::parallel_feedback::Reserved8)] pub reserved_8: u8,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 1)]
    pub struct ZmRpdo1ControlAndTargetPosition {
        #[pdo(entry = zm::od::Controlword)] pub controlword: zm::od::ControlwordValue,
        #[pdo(entry = zm::od::TargetPosition)] pub target_position: zm::od::TargetPositionValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 2)]
    pub struct ZmRpdo2ProfileVelocity {
        #[pdo(entry = zm::od::ProfileVelocity)] pub profile_velocity: zm::od::ProfileVelocityValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 1)]
    pub struct ZmTpdo1StatusAndPosition {
        #[pdo(entry = zm::od::Statusword)] pub statusword: zm::od::StatuswordValue,
        #[pdo(entry = zm::od::PositionActualValue)] pub position_actual_value: zm::od::PositionActualValueValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct ZmTpdo2Velocity {
        #[pdo(entry = zm::od::VelocityActualValue)] pub velocity_actual_value: zm::od::VelocityActualValueValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 3)]
    pub struct ZmTpdo3FollowingErrorAndTorque {
        #[pdo(entry = zm::od::FollowingErrorActualValue)] pub following_error_actual_value: zm::od::FollowingErrorActualValueValue,
        #[pdo(entry = zm::od::TorqueActualValue)] pub torque_actual_value: zm::od::TorqueActualValueValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 1)]
    pub struct IrRpdo1VelocityCommand {
        #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
        #[pdo(entry = ir::od::ModesOfOperation)] pub modes_of_operation: ir::od::ModesOfOperationValue,
        #[pdo(entry = ir::od::ProfileVelocity)] pub profile_velocity: ir::od::ProfileVelocityValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 2)]
    pub struct IrRpdo2PositionCommand {
        #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
        #[pdo(entry = ir::od::TargetPosition)] pub target_position: ir::od::TargetPositionValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(rpdo = 3)]
    pub struct IrRpdo3TargetVelocityCommand {
        #[pdo(entry = ir::od::Controlword)] pub controlword: ir::od::ControlwordValue,
        #[pdo(entry = ir::od::TargetVelocity)] pub target_velocity: ir::od::TargetVelocityValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 1)]
    pub struct IrTpdo1Status {
        #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
        #[pdo(entry = ir::od::ModesOfOperationDisplay)] pub modes_of_operation_display: ir::od::ModesOfOperationDisplayValue,
        #[pdo(entry = ir::od::ErrorRegister)] pub error_register: ir::od::ErrorRegisterValue,
        #[pdo(entry = ir::od::monitoring_values::ActualTemperature)] pub actual_temperature: ir::od::monitoring_values::ActualTemperatureValue,
        #[pdo(entry = ir::od::TorqueActualValue)] pub torque_actual_value: ir::od::TorqueActualValueValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct IrTpdo2Position {
        #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
        #[pdo(entry = ir::od::PositionActualValue)] pub position_actual_value: ir::od::PositionActualValueValue,
    }
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 3)]
    pub struct IrTpdo3Velocity {
        #[pdo(entry = ir::od::Statusword)] pub statusword: ir::od::StatuswordValue,
        #[pdo(entry = ir::od::VelocityActualValue)] pub velocity_actual_value: ir::od::VelocityActualValueValue,
    }
}

/// Where a PDO is and what it carries.
struct Meta {
    device: &'static str,
    node_id: u8,
    kind: &'static str,
    number: u16,
    label: &'static str,
    /// How many of the values are mapped fields (the rest are bits).
    mapped: usize,
}

/// ns per frame: [generated, derived, hand-written].
type Triple = [f64; 3];

/// One PDO: its frames, the generated values of each frame, and the timings.
struct Case {
    meta: Meta,
    len: usize,
    frames: Vec<Frame>,
    values: Vec<Vec<i64>>,
    decode: Triple,
    encode: Triple,
}

/// Batches per measurement and frame operations per batch.
#[derive(Clone, Copy)]
struct Plan {
    batches: usize,
    ops: usize,
}

/// Median ns per frame of `a`, `b` and `c`, timed in batches whose order
/// rotates so that drift hits all three.
fn triple(
    plan: Plan,
    frames: usize,
    mut a: impl FnMut(usize),
    mut b: impl FnMut(usize),
    mut c: impl FnMut(usize),
) -> Triple {
    let passes = plan.ops.div_ceil(frames);
    a(passes); // warm-up
    b(passes);
    c(passes);
    let mut samples = [Vec::new(), Vec::new(), Vec::new()];
    for batch in 0..plan.batches {
        for k in 0..3 {
            let which = (batch + k) % 3;
            let start = Instant::now();
            let run: &mut dyn FnMut(usize) = match which {
                0 => &mut a,
                1 => &mut b,
                _ => &mut c,
            };
            run(passes); // one dynamic call per batch; the loops inside are monomorphic
            let ns = start.elapsed().as_nanos() as f64;
            samples[which].push(ns / (passes * frames) as f64);
        }
    }
    samples.map(|mut s| {
        s.sort_by(f64::total_cmp);
        s[s.len() / 2]
    })
}

/// Runs `f` on every item, `passes` times; each item through `black_box`,
/// so that neither its bytes nor its length are known to the compiler.
#[inline(always)]
fn each<T, R>(items: &[T], passes: usize, mut f: impl FnMut(&T) -> R) {
    let (chunks, rest) = items.as_chunks::<UNROLL>();
    assert!(rest.is_empty(), "frames come in chunks of {UNROLL}");
    for _ in 0..passes {
        for chunk in chunks {
            for item in chunk {
                f(black_box(item));
            }
        }
    }
}

/// `items` repeated to `n` items.
fn repeated<T: Copy>(items: &[T], n: usize) -> Vec<T> {
    items.iter().copied().cycle().take(n).collect()
}

/// Frames per unrolled step of the timing loops: the loop's own branch and
/// its place in the instruction cache weigh 1/16 of a frame, so that the
/// same instructions time the same wherever the linker puts them.
const UNROLL: usize = 16;

/// What a receiver does with a decoded frame: hands the struct on when the
/// frame was valid (`black_box` stands for the code that uses it). The same
/// for all three codecs, so that the timing is the decoding: keeping the
/// whole `Option` instead times how the compiler spills it, which differs
/// between a `Result` turned into an `Option` and a plain `Option` even where
/// the decoding instructions are the same.
#[inline(always)]
fn deliver<T>(decoded: Option<T>) {
    if let Some(value) = decoded {
        black_box(value);
    }
}

/// Checks one PDO (generated against hand-written, both against the frames
/// and the error paths) and times it.
#[allow(clippy::too_many_arguments)]
fn case<G: Pdo + Copy, D: Pdo + Copy, H: Copy, const N: usize, const K: usize>(
    plan: Plan,
    meta: Meta,
    frames: Vec<Frame>,
    gen_decode: impl Fn(&[u8]) -> Option<G> + Copy,
    gen_encode: impl Fn(&G) -> [u8; N] + Copy,
    gen_values: impl Fn(&G) -> [i64; K] + Copy,
    der_decode: impl Fn(&[u8]) -> Option<D> + Copy,
    der_encode: impl Fn(&D) -> [u8; N] + Copy,
    hand_decode: impl Fn(&[u8]) -> Option<H> + Copy,
    hand_encode: impl Fn(&H) -> [u8; N] + Copy,
    hand_values: impl Fn(&H) -> [i64; K] + Copy,
) -> Case {
    let what = format!("{} {}", meta.device, meta.label);
    assert_eq!(G::LEN, N, "{what}: LEN");
    let decoded = |f: &Frame| {
        (
            gen_decode(f.bytes()).unwrap(),
            hand_decode(f.bytes()).unwrap(),
        )
    };
    let (gens, hands): (Vec<G>, Vec<H>) = frames.iter().map(decoded).unzip();
    // The derived struct has the generated one's mapping and field types,
    // so it must give the same bytes back for every frame.
    assert_eq!(D::MAPPING, G::MAPPING, "{what}: derived mapping");
    let ders: Vec<D> = frames
        .iter()
        .map(|f| der_decode(f.bytes()).unwrap())
        .collect();
    for (((f, g), h), d) in frames.iter().zip(&gens).zip(&hands).zip(&ders) {
        let (ours, theirs) = (gen_values(g), hand_values(h));
        assert_eq!(ours, theirs, "{what}: values of {:02X?}", f.bytes());
        assert_eq!(gen_encode(g), f.bytes(), "{what}: generated encode");
        assert_eq!(der_encode(d), f.bytes(), "{what}: derived encode");
        assert_eq!(hand_encode(h), f.bytes(), "{what}: hand-written encode");
    }
    for bad in [&[0u8; 8][..N - 1], &[0u8; 9][..N + 1], &[]] {
        let all =
            gen_decode(bad).is_none() && der_decode(bad).is_none() && hand_decode(bad).is_none();
        assert!(all, "{what}: {} bytes decode", bad.len());
    }
    // Timed: the frames repeated to a whole number of unrolled steps.
    let n = frames.len().div_ceil(UNROLL) * UNROLL;
    let (t_frames, t_gens) = (repeated(&frames, n), repeated(&gens, n));
    let (t_ders, t_hands) = (repeated(&ders, n), repeated(&hands, n));
    let decode = triple(
        plan,
        n,
        |p| each(&t_frames, p, |f| deliver(gen_decode(f.bytes()))),
        |p| each(&t_frames, p, |f| deliver(der_decode(f.bytes()))),
        |p| each(&t_frames, p, |f| deliver(hand_decode(f.bytes()))),
    );
    let encode = triple(
        plan,
        n,
        |p| each(&t_gens, p, |g| black_box(gen_encode(g))),
        |p| each(&t_ders, p, |d| black_box(der_encode(d))),
        |p| each(&t_hands, p, |h| black_box(hand_encode(h))),
    );
    let values = gens.iter().map(|g| gen_values(g).to_vec()).collect();
    let len = N;
    Case {
        meta,
        len,
        frames,
        values,
        decode,
        encode,
    }
}

/// `pdo!(plan, module, "label", mapped fields, frames, Generated, Derived, values, HandWritten, values)`.
macro_rules! pdo {
    ($plan:expr, $m:ident, $label:literal, $mapped:literal, $frames:expr,
     $g:ident, $d:ident, $gv:path, $h:ident, $hv:path) => {{
        let kind = match <$m::pdo::$g as Pdo>::DIRECTION {
            eds2rust_runtime::od::PdoDirection::Tpdo => "tpdo",
            eds2rust_runtime::od::PdoDirection::Rpdo => "rpdo",
        };
        let number = <$m::pdo::$g as Pdo>::NUMBER;
        let device = match stringify!($m) { "lk" => "linak_techline", "zm" => "zimmer_acs", _ => "interroll_ec5000bi" };
        let meta = Meta { device, node_id: $m::DEFAULT_NODE_ID, kind, number, label: $label, mapped: $mapped };
        case($plan, meta, $frames, |d| $m::pdo::$g::decode(d).ok(), $m::pdo::$g::encode, $gv,
             |d| derived::$d::decode(d).ok(), derived::$d::encode,
             hand::$h::decode, hand::$h::encode, $hv)
    }};
}

#[rustfmt::skip]
fn cases(p: Plan) -> Vec<Case> {
    use values::*;
    // The LINAK manual's start-up trace (p. 28, node 32).
    let lk_feedback = hex_frames(&["1A 00 06 88 00 31 00 C0", "F7 01 00 82 00 00 00 C0", "60 00 06 90 00 32 00 C0",
                                   "00 00 00 81 01 00 00 C0", "00 00 00 81 00 00 00 C0"]);
    // Stop, run out, run in (trace), and a 12.3 mm set point with the other fields at their defaults.
    let lk_command = hex_frames(&["03 FB FB FB FB FB 00 00", "01 FB FB FB FB FB 00 00", "02 FB FB FB FB FB 00 00",
                                  "7B 00 FB FB FB FB 00 00"]);
    let r = random_frames;
    vec![
        pdo!(p, lk, "TPDO1 feedback", 6, lk_feedback, Tpdo1Feedback, LkTpdo1Feedback, lk_tpdo1, LkFeedback, hand_lk_tpdo1),
        pdo!(p, lk, "TPDO2 parallel feedback", 8, r(12, 8, 16), Tpdo2ParallelFeedback, LkTpdo2ParallelFeedback, lk_tpdo2, LkParallel, hand_lk_tpdo2),
        pdo!(p, lk, "RPDO1 command", 7, lk_command, Rpdo1Command, LkRpdo1Command, lk_rpdo1, LkCommand, hand_lk_rpdo1),
        pdo!(p, zm, "TPDO1 status and position", 2, r(21, 6, 16), Tpdo1StatusAndPosition, ZmTpdo1StatusAndPosition, zm_tpdo1, WordAnd32, hand_zm_tpdo1),
        pdo!(p, zm, "TPDO2 velocity", 1, r(22, 4, 16), Tpdo2Velocity, ZmTpdo2Velocity, zm_tpdo2, One32, hand_i32),
        pdo!(p, zm, "TPDO3 following error and torque", 2, r(23, 6, 16), Tpdo3FollowingErrorAndTorque, ZmTpdo3FollowingErrorAndTorque, zm_tpdo3,
             ZmFollowingTorque, hand_zm_tpdo3),
        pdo!(p, zm, "RPDO1 control and target position", 2, r(24, 6, 16), Rpdo1ControlAndTargetPosition, ZmRpdo1ControlAndTargetPosition, zm_rpdo1,
             WordAnd32, hand_zm_rpdo1),
        pdo!(p, zm, "RPDO2 profile velocity", 1, r(25, 4, 16), Rpdo2ProfileVelocity, ZmRpdo2ProfileVelocity, zm_rpdo2, One32, hand_u32),
        pdo!(p, ir, "TPDO1 status", 5, r(31, 8, 16), Tpdo1Status, IrTpdo1Status, ir_tpdo1, IrStatus, hand_ir_tpdo1),
        pdo!(p, ir, "TPDO2 position", 2, r(32, 6, 16), Tpdo2Position, IrTpdo2Position, ir_tpdo2, WordAnd32, hand_ir_tpdo23),
        pdo!(p, ir, "TPDO3 velocity", 2, r(33, 6, 16), Tpdo3Velocity, IrTpdo3Velocity, ir_tpdo3, WordAnd32, hand_ir_tpdo23),
        pdo!(p, ir, "RPDO1 velocity command", 3, r(34, 7, 16), Rpdo1VelocityCommand, IrRpdo1VelocityCommand, ir_rpdo1, IrVelocityCommand,
             hand_ir_rpdo1),
        pdo!(p, ir, "RPDO2 position command", 2, r(35, 6, 16), Rpdo2PositionCommand, IrRpdo2PositionCommand, ir_rpdo2, WordAnd32, hand_ir_rpdo23),
        pdo!(p, ir, "RPDO3 target velocity command", 2, r(36, 6, 16), Rpdo3TargetVelocityCommand, IrRpdo3TargetVelocityCommand, ir_rpdo3, WordAnd32,
             hand_ir_rpdo23),
    ]
}

/// Exports the seed devices as EDS, runs `bench_pdo.py` on every case's
/// frames, checks that its raw values and encodings agree with ours, and
/// returns its ns per frame ([decode, encode]) per case and a header line.
fn python(cases: &[Case]) -> (Vec<[f64; 2]>, String) {
    let dir = eds2rust_tests::target_dir().join("pdo_codec");
    std::fs::create_dir_all(&dir).expect("create target/pdo_codec");
    let mut pdos = Vec::new();
    let mut exported = std::collections::BTreeSet::new();
    for c in cases {
        let eds = dir.join(format!("{}.eds", c.meta.device));
        if exported.insert(c.meta.device) {
            let root = eds2rust_tests::workspace_root();
            let yaml = root.join(format!("eds/{}.yaml", c.meta.device));
            let options = eds2rust::input::Options::strict();
            let device = eds2rust::input::read_device(&yaml, &options)
                .device
                .expect("seed device");
            std::fs::write(&eds, eds2rust::r#gen::to_eds(&device)).expect("write EDS");
        }
        let frames: Vec<&[u8]> = c.frames.iter().map(Frame::bytes).collect();
        let (node_id, kind, number) = (c.meta.node_id, c.meta.kind, c.meta.number);
        pdos.push(json!({"eds": eds, "node_id": node_id, "kind": kind, "number": number, "frames": frames}));
    }
    let spec = dir.join("spec.json");
    let text = json!({"min_batch_ops": 1000, "pdos": pdos}).to_string();
    std::fs::write(&spec, text).expect("write spec");
    let extra = ["--batches", "21"];
    let out = eds2rust_tests::python::run_script("bench_pdo.py", &[spec.as_path()], &extra)
        .unwrap_or_else(|e| panic!("python-canopen benchmark failed: {e}"));
    let line = out
        .lines()
        .last()
        .expect("bench_pdo.py prints one JSON line");
    let result: Json = serde_json::from_str(line).expect("bench_pdo.py prints JSON");
    let mut times = Vec::new();
    for (c, py) in cases.iter().zip(result["pdos"].as_array().expect("pdos")) {
        let what = format!("{} {} (python-canopen)", c.meta.device, c.meta.label);
        let raws: Vec<Vec<i64>> = serde_json::from_value(py["raw"].clone()).expect("raw");
        let encoded: Vec<Vec<u8>> = serde_json::from_value(py["encoded"].clone()).expect("encoded");
        assert_eq!(raws.len(), c.frames.len(), "{what}: frames");
        for (((f, ours), theirs), enc) in c.frames.iter().zip(&c.values).zip(&raws).zip(&encoded) {
            let (ours, f) = (&ours[..c.meta.mapped], f.bytes());
            assert_eq!(ours, theirs.as_slice(), "{what}: raw values of {f:02X?}");
            assert_eq!(enc.as_slice(), f, "{what}: encoded");
        }
        let ns = |key: &str| py[key].as_f64().expect("ns per frame");
        times.push([ns("decode_ns"), ns("encode_ns")]);
    }
    let mut header = format!(
        "python-canopen {} (Python {}): median of {} batches of >= 1000 frames; its raw values and encodings agree with ours on every frame of all {} PDOs",
        result["canopen"].as_str().unwrap_or("?"),
        result["python"].as_str().unwrap_or("?"),
        result["batches"],
        cases.len()
    );
    for note in result["notes"].as_array().into_iter().flatten() {
        header += &format!("\n  note: {}", note.as_str().unwrap_or("?"));
    }
    (times, header)
}

fn geomean(xs: &[f64]) -> f64 {
    (xs.iter().map(|x| x.ln()).sum::<f64>() / xs.len() as f64).exp()
}

fn main() {
    // `cargo test --benches` runs bench binaries without `--bench`: check and time briefly, no python.
    let quick = !std::env::args().any(|a| a == "--bench");
    let (batches, ops) = if quick { (3, 1000) } else { (101, 100_000) };
    let plan = Plan { batches, ops };
    let cases = cases(plan);
    let (py, header) = match quick {
        true => (
            vec![[f64::NAN; 2]; cases.len()],
            "python-canopen: not run (quick mode)".into(),
        ),
        false => python(&cases),
    };
    println!(
        "pdo_codec: ns per frame; Rust: median of {batches} batches of >= {ops} frames, generated, derived (`#[derive(Pdo)]`, same mapping) and hand-written in rotating batches"
    );
    println!("{header}");
    // [generated/hand-written, derived/hand-written] per row.
    let mut ratios: [Vec<(f64, String)>; 2] = Default::default();
    let mut py_ratios: Vec<(f64, String)> = Vec::new();
    for (c, py) in cases.iter().zip(&py) {
        let name = format!("{} {}", c.meta.device, c.meta.label);
        let (len, mapped, values, frames) =
            (c.len, c.meta.mapped, c.values[0].len(), c.frames.len());
        println!(
            "\n{name}: {len} bytes, {mapped} mapped fields, {values} values with bits, {frames} frames"
        );
        println!(
            "  {:<8}generated    derived  hand-written  python-canopen  gen/hand  der/hand  python/gen",
            ""
        );
        let rows = [("decode", c.decode, py[0]), ("encode", c.encode, py[1])];
        for (op, [g, d, h], p) in rows {
            let (py_col, ratio_col) = if p.is_nan() {
                ("-".to_string(), "-".to_string())
            } else {
                py_ratios.push((p / g, format!("{name} {op}")));
                (format!("{p:.0} ns"), format!("{:.0}x", p / g))
            };
            ratios[0].push((g / h, format!("{name} {op} (generated)")));
            ratios[1].push((d / h, format!("{name} {op} (derived)")));
            println!(
                "  {op:<6} {g:>8.2} ns {d:>7.2} ns {h:>10.2} ns {py_col:>15} {:>8.3}x {:>8.3}x {ratio_col:>11}",
                g / h,
                d / h
            );
        }
    }
    println!();
    let ratio_list = |rs: &[(f64, String)]| rs.iter().map(|r| r.0).collect::<Vec<f64>>();
    for (what, rs) in ["generated", "derived"].iter().zip(&ratios) {
        let (max, which) = rs.iter().max_by(|a, b| a.0.total_cmp(&b.0)).expect("cases");
        let mean = geomean(&ratio_list(rs));
        let over: Vec<String> = rs
            .iter()
            .filter(|r| r.0 > 1.05)
            .map(|r| format!("{} {:.2}x", r.1, r.0))
            .collect();
        let verdict = match over.len() {
            _ if quick => "not judged (a quick check, not a measurement: run with --bench)".into(),
            0 => "met".to_string(),
            n => format!("MISSED in {n} of {} rows: {}", rs.len(), over.join(", ")),
        };
        println!(
            "summary: {what}/hand-written geometric mean {mean:.3}x, max {max:.3}x ({which}); goal <= 1.05x per row: {verdict}"
        );
    }
    if let Some((min, which)) = py_ratios.iter().min_by(|a, b| a.0.total_cmp(&b.0)) {
        let (mean, verdict) = (
            geomean(&ratio_list(&py_ratios)),
            if *min >= 1000.0 { "met" } else { "MISSED" },
        );
        println!(
            "summary: python-canopen/generated geometric mean {mean:.0}x, min {min:.0}x ({which}); goal >= 1000x: {verdict}"
        );
    }
}
