//! The PDO mapping of ../generated over entries written by hand: the three
//! objects it maps, as the generator would declare them, with plain
//! integers for their values.
#![no_std]
#![forbid(unsafe_code)]

/// The drive's objects the application maps.
pub mod od {
    use eds2rust_runtime::od::{DataType, Entry, PdoMappable, access};

    /// 0x6041 statusword.
    pub struct Statusword;
    impl Entry for Statusword {
        const INDEX: u16 = 0x6041;
        const NAME: &'static str = "statusword";
        const DATA_TYPE: DataType = DataType::Unsigned16;
        const PDO_MAPPABLE: bool = true;
        type Access = access::Ro;
        type Value = u16;
    }
    impl PdoMappable for Statusword {}

    /// 0x6064 position actual value.
    pub struct PositionActualValue;
    impl Entry for PositionActualValue {
        const INDEX: u16 = 0x6064;
        const NAME: &'static str = "position_actual_value";
        const DATA_TYPE: DataType = DataType::Integer32;
        const PDO_MAPPABLE: bool = true;
        type Access = access::Ro;
        type Value = i32;
    }
    impl PdoMappable for PositionActualValue {}

    /// 0x6061 modes of operation display.
    pub struct ModesOfOperationDisplay;
    impl Entry for ModesOfOperationDisplay {
        const INDEX: u16 = 0x6061;
        const NAME: &'static str = "modes_of_operation_display";
        const DATA_TYPE: DataType = DataType::Integer8;
        const PDO_MAPPABLE: bool = true;
        type Access = access::Ro;
        type Value = i8;
    }
    impl PdoMappable for ModesOfOperationDisplay {}
}

/// The PDOs the application maps.
pub mod mapping {
    use crate::od;
    use eds2rust_runtime::Pdo;

    /// What the control loop reads: statusword, position and the mode the
    /// drive is in.
    #[derive(Pdo, Debug, Clone, Copy, PartialEq)]
    #[pdo(tpdo = 2)]
    pub struct StatusPosition {
        #[pdo(entry = od::Statusword)]
        pub status: u16,
        #[pdo(entry = od::PositionActualValue)]
        pub position: i32,
        #[pdo(entry = od::ModesOfOperationDisplay)]
        pub mode: i8,
    }
}
