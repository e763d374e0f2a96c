//! The fastscan search of CiA 305 as a sans-IO sub-state machine: it says
//! which request to send, and is told after each one whether any slave
//! answered within the timeout.
//!
//! The scan first sends the confirm request (bit check 0x80): every
//! non-configured slave in the waiting state resets its scan and answers;
//! silence means there is none. Then, for each address part (LSS sub 0 to
//! 3), bit by bit from 31 down to 0, it sends the bits found so far with the
//! current bit 0 and bit check = the current bit: a slave whose bits 31 down
//! to the current one equal the candidate answers. No answer means every
//! remaining slave has a 1 there, so the bit is set. After bit 0 the part is
//! verified (bit check 0, LSS next = the next part); the slave that matches
//! moves on to the next part, and after the last part (LSS next 0 < LSS sub
//! 3) it enters the configuration state. Known parts skip their bit scan.

use crate::lss::proto::FastscanRequest;
use crate::lss::{Identity, IdentityField};

/// Parts of the LSS address the master already knows; fastscan only
/// verifies them instead of scanning their 32 bits. With none known (the
/// default) the search takes 133 steps of one timeout at most.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct KnownIdentity {
    /// Vendor id, if known.
    pub vendor_id: Option<u32>,
    /// Product code, if known.
    pub product_code: Option<u32>,
    /// Revision number, if known.
    pub revision: Option<u32>,
    /// Serial number, if known.
    pub serial: Option<u32>,
}

impl KnownIdentity {
    /// Nothing known: all 128 bits are scanned.
    pub const NONE: KnownIdentity = KnownIdentity {
        vendor_id: None,
        product_code: None,
        revision: None,
        serial: None,
    };

    /// The known value of `field`, if any.
    pub const fn get(&self, field: IdentityField) -> Option<u32> {
        match field {
            IdentityField::VendorId => self.vendor_id,
            IdentityField::ProductCode => self.product_code,
            IdentityField::Revision => self.revision,
            IdentityField::Serial => self.serial,
        }
    }
}

/// Where the scan stands: the request it is waiting on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Step {
    /// The confirm request (bit check 0x80).
    Confirm,
    /// Checking bits 31 down to this one of the current part.
    Bit(u8),
    /// Verifying the whole current part (bit check 0, LSS next set).
    Verify,
}

/// What the scan does after a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Progress {
    /// Send [`Fastscan::request`] and report again.
    Continue,
    /// The slave with this address answered the last verification and is
    /// now in the configuration state.
    Found(Identity),
    /// No non-configured slave answered (or one stopped answering).
    NotFound,
}

/// The fastscan search in progress.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fastscan {
    known: KnownIdentity,
    found: Identity,
    field: IdentityField,
    step: Step,
}

impl Fastscan {
    /// A scan about to send its confirm request.
    pub(crate) const fn new(known: KnownIdentity) -> Fastscan {
        Fastscan {
            known,
            found: Identity::new(0, 0, 0, 0),
            field: IdentityField::VendorId,
            step: Step::Confirm,
        }
    }

    /// The request of the current step.
    pub(crate) fn request(&self) -> FastscanRequest {
        let sub = self.field.index();
        let id_number = self.found.get(self.field);
        match self.step {
            Step::Confirm => FastscanRequest::CONFIRM,
            Step::Bit(bit) => FastscanRequest {
                id_number,
                bit_check: bit,
                sub,
                next: sub,
            },
            Step::Verify => FastscanRequest {
                id_number,
                bit_check: 0,
                sub,
                next: next_field(self.field).index(),
            },
        }
    }

    /// Records whether any slave answered the current request within the
    /// timeout and moves to the next step.
    pub(crate) fn advance(&mut self, answered: bool) -> Progress {
        match self.step {
            Step::Confirm => {
                if !answered {
                    return Progress::NotFound;
                }
                self.start_field(IdentityField::VendorId);
            }
            Step::Bit(bit) => {
                if !answered {
                    let value =
                        self.found.get(self.field) | 1u32.checked_shl(bit.into()).unwrap_or(0);
                    self.found.set(self.field, value);
                }
                self.step = match bit.checked_sub(1) {
                    Some(lower) => Step::Bit(lower),
                    None => Step::Verify,
                };
            }
            Step::Verify => {
                if !answered {
                    return Progress::NotFound;
                }
                if self.field == IdentityField::Serial {
                    return Progress::Found(self.found);
                }
                self.start_field(next_field(self.field));
            }
        }
        Progress::Continue
    }

    /// Starts on `field`: verify a known value, else scan from bit 31.
    fn start_field(&mut self, field: IdentityField) {
        self.field = field;
        match self.known.get(field) {
            Some(value) => {
                self.found.set(field, value);
                self.step = Step::Verify;
            }
            None => {
                self.found.set(field, 0);
                self.step = Step::Bit(31);
            }
        }
    }
}

/// The part scanned after `field` (the serial number wraps to the vendor
/// id, which ends the scan in the slave).
const fn next_field(field: IdentityField) -> IdentityField {
    match field {
        IdentityField::VendorId => IdentityField::ProductCode,
        IdentityField::ProductCode => IdentityField::Revision,
        IdentityField::Revision => IdentityField::Serial,
        IdentityField::Serial => IdentityField::VendorId,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Answers like a single slave with `id` would (ignoring its scan
    /// position, which the scan itself keeps in step).
    fn answers(id: &Identity, request: &FastscanRequest) -> bool {
        if request.bit_check == 0x80 {
            return true;
        }
        let Some(field) = IdentityField::from_index(request.sub) else {
            return false;
        };
        let mask = u32::MAX.checked_shl(request.bit_check.into()).unwrap_or(0);
        id.get(field) & mask == request.id_number & mask
    }

    fn run(slave: Option<Identity>, known: KnownIdentity) -> (Progress, usize) {
        let mut scan = Fastscan::new(known);
        for steps in 1..=200 {
            let request = scan.request();
            assert!(request.is_valid());
            let answered = slave.is_some_and(|id| answers(&id, &request));
            match scan.advance(answered) {
                Progress::Continue => {}
                done => return (done, steps),
            }
        }
        panic!("the scan did not end");
    }

    #[test]
    fn finds_every_bit_in_133_steps() {
        for id in [
            Identity::new(0, 0, 0, 0),
            Identity::new(u32::MAX, u32::MAX, u32::MAX, u32::MAX),
            Identity::new(0x0000_017A, 0x1234_5678, 0x0001_0003, 0x8000_0001),
        ] {
            assert_eq!(
                run(Some(id), KnownIdentity::NONE),
                (Progress::Found(id), 133)
            );
        }
    }

    #[test]
    fn known_parts_are_only_verified() {
        let id = Identity::new(0x17A, 2, 3, 4);
        let known = KnownIdentity {
            vendor_id: Some(0x17A),
            product_code: Some(2),
            ..KnownIdentity::NONE
        };
        // Confirm, 2 verifications, 2 × (32 bits + verification).
        assert_eq!(run(Some(id), known), (Progress::Found(id), 1 + 2 + 66));
        let wrong = KnownIdentity {
            vendor_id: Some(0x17B),
            ..KnownIdentity::NONE
        };
        assert_eq!(run(Some(id), wrong), (Progress::NotFound, 2));
    }

    #[test]
    fn silence_ends_after_the_confirm_request() {
        assert_eq!(run(None, KnownIdentity::NONE), (Progress::NotFound, 1));
    }

    /// The request with these fields.
    fn req(id_number: u32, bit_check: u8, sub: u8, next: u8) -> FastscanRequest {
        FastscanRequest {
            id_number,
            bit_check,
            sub,
            next,
        }
    }

    #[test]
    fn request_fields() {
        let mut scan = Fastscan::new(KnownIdentity::NONE);
        assert_eq!(scan.request(), FastscanRequest::CONFIRM);
        scan.advance(true);
        assert_eq!(scan.request(), req(0, 31, 0, 0));
        scan.advance(false); // bit 31 is 1
        assert_eq!(scan.request(), req(0x8000_0000, 30, 0, 0));
        for _ in 0..31 {
            scan.advance(true);
        }
        assert_eq!(scan.request(), req(0x8000_0000, 0, 0, 1));
        scan.advance(true);
        assert_eq!(scan.request(), req(0, 31, 1, 1));
    }
}
