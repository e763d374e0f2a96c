// The SDO client offers no write of a read-only object (LINAK feedback position).
use eds2rust_drivers::linak_techline::od::feedback;
use eds2rust_drivers::runtime::blocking::SdoClient;
use eds2rust_drivers::runtime::sdo::Channel;
use eds2rust_drivers::runtime::sdo::client::ClientConfig;
use eds2rust_drivers::runtime::transport::virtual_bus::VirtualBus;

fn main() {
    let bus = VirtualBus::new();
    let channel = Channel::default_for(eds2rust_drivers::runtime::od::NodeId::new(32).unwrap());
    let mut client = SdoClient::new(bus.attach(), ClientConfig::new(channel));
    let _ = client.write::<feedback::Position>(feedback::PositionValue::from_raw(26));
}
