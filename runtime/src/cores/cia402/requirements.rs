//! Which objects each CiA 402 operation needs, checked against a device's
//! object table before any SDO traffic.
//!
//! The table follows what [`Drive`](super::Drive) writes and reads, plus
//! what the mode needs to work at all:
//!
//! | operation | writes | reads |
//! |---|---|---|
//! | [`Operation::StateMachine`] (enable, disable, quick stop, fault reset) | 0x6040 | 0x6041 |
//! | [`Operation::ProfilePosition`] | 0x6060, 0x607A | |
//! | [`Operation::ProfileVelocity`] | 0x6060, 0x60FF | |
//! | [`Operation::Homing`] | 0x6060, 0x6098 | |
//! | [`Operation::CyclicSynchronousPosition`] | 0x6060, 0x607A | |
//! | [`Operation::MotionProfile`] ([`Drive::set_profile`](super::Drive::set_profile)) | 0x6081, 0x6083, 0x6084 | |
//!
//! 0x603F (error code) is optional: the error of a fault names it when the
//! device has it ([`has_error_code`]).
//!
//! The check is a `const fn`, so a generated table can be checked at
//! compile time:
//!
//! ```
//! use eds2rust_runtime::cia402::requirements::{Operation, assert_supported};
//! use eds2rust_runtime::od::{AccessRight, DataType, ObjectInfo};
//!
//! const OBJECTS: &[ObjectInfo] = &[
//!     ObjectInfo::new(0x6040, 0, "Controlword", DataType::Unsigned16, AccessRight::Rw, true),
//!     ObjectInfo::new(0x6041, 0, "Statusword", DataType::Unsigned16, AccessRight::Ro, true),
//!     ObjectInfo::new(0x6060, 0, "Modes of operation", DataType::Integer8, AccessRight::Rw, true),
//!     ObjectInfo::new(0x607A, 0, "Target position", DataType::Integer32, AccessRight::Rw, true),
//! ];
//! // Fails to compile when the device lacks an object profile position needs.
//! const _: () = assert_supported(OBJECTS, &[Operation::StateMachine, Operation::ProfilePosition]);
//! assert!(Operation::ProfileVelocity.check(OBJECTS).is_err());
//! ```

use core::fmt;

use super::object;
use crate::od::{AccessRight, ObjectInfo};

/// A group of drive functions with the objects they need.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Operation {
    /// The power state machine: enable, disable, quick stop, fault reset.
    StateMachine,
    /// Profile position moves (mode 1).
    ProfilePosition,
    /// Profile velocity (mode 3).
    ProfileVelocity,
    /// Homing (mode 6).
    Homing,
    /// Cyclic synchronous position (mode 8).
    CyclicSynchronousPosition,
    /// Profile velocity, acceleration and deceleration parameters.
    MotionProfile,
}

/// How an operation uses an object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Use {
    /// The master writes it.
    Write,
    /// The master reads it.
    Read,
}

/// One object an operation needs (sub-index 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Requirement {
    /// The object index.
    pub index: u16,
    /// The CiA 402 name of the object.
    pub name: &'static str,
    /// How the operation uses it.
    pub usage: Use,
    /// What [`assert_supported`] says when a table lacks it (a compile-time
    /// panic takes no formatted message).
    pub missing: &'static str,
}

/// A requirement: `need!(write, 0x60FF, "Target velocity")`.
macro_rules! need {
    ($usage:ident, $index:literal, $name:literal) => {
        Requirement {
            index: $index,
            name: $name,
            usage: need!(@ $usage),
            missing: concat!(
                "this device has no ",
                need!(@text $usage),
                " ",
                stringify!($index),
                " ",
                $name,
                ", which an operation of this assertion needs"
            ),
        }
    };
    (@ write) => {
        Use::Write
    };
    (@text write) => {
        "writable"
    };
    (@text read) => {
        "readable"
    };
    (@ read) => {
        Use::Read
    };
}

const MODES: Requirement = need!(write, 0x6060, "Modes of operation");
const TARGET_POSITION: Requirement = need!(write, 0x607A, "Target position");

impl Operation {
    /// Every operation.
    pub const ALL: [Operation; 6] = [
        Operation::StateMachine,
        Operation::ProfilePosition,
        Operation::ProfileVelocity,
        Operation::Homing,
        Operation::CyclicSynchronousPosition,
        Operation::MotionProfile,
    ];

    /// The name used in messages ("profile velocity").
    pub const fn name(self) -> &'static str {
        match self {
            Operation::StateMachine => "the CiA 402 state machine",
            Operation::ProfilePosition => "profile position",
            Operation::ProfileVelocity => "profile velocity",
            Operation::Homing => "homing",
            Operation::CyclicSynchronousPosition => "cyclic synchronous position",
            Operation::MotionProfile => "the motion profile",
        }
    }

    /// The objects the operation needs.
    pub const fn requirements(self) -> &'static [Requirement] {
        const STATE_MACHINE: &[Requirement] = &[
            need!(write, 0x6040, "Controlword"),
            need!(read, 0x6041, "Statusword"),
        ];
        const PROFILE_POSITION: &[Requirement] = &[MODES, TARGET_POSITION];
        const PROFILE_VELOCITY: &[Requirement] = &[MODES, need!(write, 0x60FF, "Target velocity")];
        const HOMING: &[Requirement] = &[MODES, need!(write, 0x6098, "Homing method")];
        const MOTION_PROFILE: &[Requirement] = &[
            need!(write, 0x6081, "Profile velocity"),
            need!(write, 0x6083, "Profile acceleration"),
            need!(write, 0x6084, "Profile deceleration"),
        ];
        match self {
            Operation::StateMachine => STATE_MACHINE,
            Operation::ProfilePosition | Operation::CyclicSynchronousPosition => PROFILE_POSITION,
            Operation::ProfileVelocity => PROFILE_VELOCITY,
            Operation::Homing => HOMING,
            Operation::MotionProfile => MOTION_PROFILE,
        }
    }

    /// Checks `objects` (a device's object table, such as a generated
    /// `od::OBJECTS`) for every object the operation needs, with an access
    /// right that allows its use; the first one missing is the error.
    pub const fn check(self, objects: &[ObjectInfo]) -> Result<(), MissingObject> {
        let needs = self.requirements();
        let mut i = 0;
        while i < needs.len() {
            let need = needs[i];
            let problem = match find(objects, need.index) {
                None => Some(Problem::Absent),
                Some(access) => match need.usage {
                    Use::Write if !writable(access) => Some(Problem::NotWritable(access)),
                    Use::Read if !readable(access) => Some(Problem::NotReadable(access)),
                    _ => None,
                },
            };
            if let Some(problem) = problem {
                return Err(MissingObject {
                    operation: self,
                    requirement: need,
                    problem,
                });
            }
            i += 1;
        }
        Ok(())
    }
}

/// Panics (at compile time in a `const`) when `objects` lacks an object one
/// of `operations` needs; see the module example.
pub const fn assert_supported(objects: &[ObjectInfo], operations: &[Operation]) {
    let mut i = 0;
    while i < operations.len() {
        if let Err(e) = operations[i].check(objects) {
            panic!("{}", e.requirement.missing);
        }
        i += 1;
    }
}

/// Whether `objects` has a readable error code (0x603F).
pub const fn has_error_code(objects: &[ObjectInfo]) -> bool {
    match find(objects, object::ERROR_CODE) {
        Some(access) => readable(access),
        None => false,
    }
}

/// The access right of sub-index 0 of `index` in `objects`.
const fn find(objects: &[ObjectInfo], index: u16) -> Option<AccessRight> {
    let mut i = 0;
    while i < objects.len() {
        if objects[i].index == index && objects[i].subindex == 0 {
            return Some(objects[i].access);
        }
        i += 1;
    }
    None
}

const fn writable(access: AccessRight) -> bool {
    matches!(
        access,
        AccessRight::Wo | AccessRight::Rw | AccessRight::Rwr | AccessRight::Rww
    )
}

const fn readable(access: AccessRight) -> bool {
    !matches!(access, AccessRight::Wo)
}

/// What is wrong with a required object.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Problem {
    /// The device has no such object.
    Absent,
    /// The object must be written but has this access right.
    NotWritable(AccessRight),
    /// The object must be read but has this access right.
    NotReadable(AccessRight),
}

/// An operation needs an object the device does not have (or not with the
/// access right it needs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub struct MissingObject {
    /// The operation.
    pub operation: Operation,
    /// The object it needs.
    pub requirement: Requirement,
    /// What is wrong.
    pub problem: Problem,
}

impl fmt::Display for MissingObject {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Requirement { index, name, .. } = self.requirement;
        write!(f, "{} needs {index:#06X} {name}", self.operation.name())?;
        match self.problem {
            Problem::Absent => f.write_str(", which this device does not have"),
            Problem::NotWritable(access) => {
                write!(f, " to be writable, but this device has it {access:?}")
            }
            Problem::NotReadable(access) => {
                write!(f, " to be readable, but this device has it {access:?}")
            }
        }
    }
}

impl core::error::Error for MissingObject {}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::od::DataType;

    const fn info(index: u16, access: AccessRight) -> ObjectInfo {
        ObjectInfo::new(index, 0, "x", DataType::Unsigned16, access, false)
    }

    const DEVICE: &[ObjectInfo] = &[
        info(0x6040, AccessRight::Rw),
        info(0x6041, AccessRight::Ro),
        info(0x6060, AccessRight::Rw),
        info(0x607A, AccessRight::Rww),
        info(0x6098, AccessRight::Ro),
    ];

    const _: () = assert_supported(
        DEVICE,
        &[Operation::StateMachine, Operation::ProfilePosition],
    );

    #[test]
    fn missing_and_read_only_objects_are_named() {
        assert_eq!(Operation::CyclicSynchronousPosition.check(DEVICE), Ok(()));
        let e = Operation::ProfileVelocity.check(DEVICE).unwrap_err();
        assert_eq!(
            e.to_string(),
            "profile velocity needs 0x60FF Target velocity, which this device does not have"
        );
        let e = Operation::Homing.check(DEVICE).unwrap_err();
        assert_eq!(e.problem, Problem::NotWritable(AccessRight::Ro));
        assert_eq!(
            e.to_string(),
            "homing needs 0x6098 Homing method to be writable, but this device has it Ro"
        );
        let e = Operation::StateMachine
            .check(&[info(0x6040, AccessRight::Rw), info(0x6041, AccessRight::Wo)])
            .unwrap_err();
        assert_eq!(e.problem, Problem::NotReadable(AccessRight::Wo));
        assert!(Operation::StateMachine.check(&[]).is_err());
        assert!(!has_error_code(DEVICE));
        assert!(has_error_code(&[info(0x603F, AccessRight::Ro)]));
    }

    #[test]
    fn every_operation_needs_something() {
        for op in Operation::ALL {
            assert!(!op.requirements().is_empty());
            assert!(op.check(&[]).is_err());
        }
    }
}
