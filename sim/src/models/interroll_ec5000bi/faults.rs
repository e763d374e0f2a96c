//! Error bookkeeping of chapters 5 and 9: which errors and warnings are
//! present, which errors await acknowledgement, and the CiA 301 error
//! register they give.

use eds2rust_drivers::interroll_ec5000bi::errors::Emcy;

/// Whether the manual classes `code` as a warning ("W", chapter 9.2);
/// everything else (F, E, no class) is an error that must be
/// acknowledged (chapter 5.2).
pub fn is_warning(code: u16) -> bool {
    Emcy::from_code(u32::from(code)).reaction() == Some("W")
}

/// Present conditions and latched errors.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(crate) struct Faults {
    /// Error conditions still present (a fault reset is refused while
    /// any is, chapter 5.2: "sobald keine Fehler mehr anliegen").
    pub(crate) present: Vec<u16>,
    /// Errors raised since the last acknowledgement.
    pub(crate) latched: Vec<u16>,
    /// Warnings present (no acknowledgement needed).
    pub(crate) warnings: Vec<u16>,
    /// Errors and warnings raised over the drive's life (for the
    /// "error quantity" status light).
    pub(crate) lifetime_count: u32,
}

impl Faults {
    /// Records `code`; returns whether it is new (and so worth an EMCY).
    pub(crate) fn raise(&mut self, code: u16) -> bool {
        let list = if is_warning(code) {
            &mut self.warnings
        } else {
            &mut self.present
        };
        if list.contains(&code) {
            return false;
        }
        list.push(code);
        if !is_warning(code) && !self.latched.contains(&code) {
            self.latched.push(code);
        }
        self.lifetime_count = self.lifetime_count.saturating_add(1);
        true
    }

    /// The condition `code` went away; returns whether it was present.
    pub(crate) fn clear(&mut self, code: u16) -> bool {
        let before = self.present.len() + self.warnings.len();
        self.present.retain(|c| *c != code);
        self.warnings.retain(|c| *c != code);
        before != self.present.len() + self.warnings.len()
    }

    /// Whether any error condition is still present.
    pub(crate) fn persists(&self) -> bool {
        !self.present.is_empty()
    }

    /// Whether nothing is signalled any more (the moment for EMCY 0x0000).
    pub(crate) fn all_clear(&self) -> bool {
        self.latched.is_empty() && self.warnings.is_empty()
    }

    /// The error register 0x1001 (CiA 301 bits; the manual maps it into
    /// TPDO1 but gives no bits): bit 0 whenever anything is signalled,
    /// bit 1 current, bit 2 voltage, bit 3 temperature, bit 4
    /// communication, bit 7 other manufacturer codes.
    pub(crate) fn error_register(&self) -> u8 {
        let mut reg = 0u8;
        for &code in self.latched.iter().chain(&self.warnings) {
            reg |= 0x01;
            reg |= match code {
                0x2000..=0x2FFF | 0xFF14 | 0xFF15 => 0x02,
                0x3000..=0x3FFF => 0x04,
                0x4000..=0x4FFF | 0xFFA8 | 0xFFA9 | 0xFFAA => 0x08,
                0x8100..=0x82FF | 0xFFD0..=0xFFD3 => 0x10,
                0xFF00..=0xFFFF => 0x80,
                _ => 0,
            };
        }
        reg
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_follow_chapter_9() {
        assert!(is_warning(0xFFA8));
        assert!(!is_warning(0x3220));
        assert!(!is_warning(0xFFBC)); // class "E"
    }

    #[test]
    fn register_and_latching() {
        let mut f = Faults::default();
        assert!(f.raise(0x3220));
        assert!(!f.raise(0x3220));
        assert_eq!(f.error_register(), 0x05);
        assert!(f.persists());
        assert!(f.clear(0x3220));
        assert!(!f.persists());
        assert!(!f.all_clear()); // still latched until acknowledged
        f.latched.clear();
        assert!(f.all_clear());
        f.raise(0xFFA8);
        assert_eq!(f.error_register(), 0x09);
    }
}
