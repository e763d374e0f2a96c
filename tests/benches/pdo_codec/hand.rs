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
