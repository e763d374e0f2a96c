// An array element outside the array's range does not compile: LINAK's
// consumer heartbeat times (0x1016) are subs 1 to 1, so sub 2 is refused.
use eds2rust_drivers::linak_techline::od::consumer_heartbeat_time::ConsumerHeartbeatTime;
use eds2rust_drivers::runtime::od::Entry;

fn main() {
    let sub = <ConsumerHeartbeatTime<2> as Entry>::SUBINDEX;
    println!("{sub}");
}
