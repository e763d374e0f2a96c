//! The generated network's boot plan: the constant `network::PLAN`, a
//! [`NetworkPlan`] written out as a Rust expression. The value comes from
//! `network::boot_plan` (the one conversion of a configured bus file into
//! a plan); this file only renders it, every list as `Cow::Borrowed` of a
//! slice so that the plan is a `const`.

use std::time::Duration;

use eds2rust_runtime::boot::{
    ConfigWrite, MasterPlan, NetworkPlan, PdoLink, SlaveConfig, SlavePlan, Supervision,
};
use eds2rust_runtime::nmt::NmtCommand;
use eds2rust_runtime::od::NodeId;
use proc_macro2::{Literal, TokenStream};
use quote::{ToTokens, quote};

use super::prim;

/// `pub const PLAN: rt::boot::NetworkPlan = ..;` with its documentation,
/// for the `network` module (which names the runtime `rt` and declares
/// `extern crate alloc`).
pub(crate) fn plan_const(plan: &NetworkPlan, rt: &TokenStream) -> TokenStream {
    let value = network(plan, rt);
    let writes = plan.slaves.iter().any(|s| !s.plan.configuration.is_empty());
    let helper = writes.then(|| {
        quote! {
            #[doc = " One entry of a slave's configuration in [`PLAN`]."]
        const fn write(index: u16, sub_index: u8, data: &'static [u8]) -> #rt::boot::ConfigWrite {
            #rt::boot::ConfigWrite {
                index,
                sub_index,
                data: alloc::borrow::Cow::Borrowed(data),
            }
        }
        }
    });
    quote! {
        #helper
        #[doc = " The network's boot plan (CiA 302-2): what the master checks, configures and starts on each slave, how it supervises them, and the PDOs it sends and receives. The same value as `eds2rust::network::boot_plan` of the bus file; give it to `Master::for_network` and `boot_network`."]
        pub const PLAN: #rt::boot::NetworkPlan = #value;
    }
}

/// `#rt::boot::Type { field: tokens, … }` of `value`, a `Type` of the
/// runtime: every field is bound by name (a field the runtime adds is a
/// compile error here) and rendered by its expression, in the order given.
macro_rules! boot_struct {
    ($rt:expr, $value:expr, $ty:ident { $($field:ident => $tokens:expr),* $(,)? }) => {{
        let $ty { $($field),* } = $value;
        // A field passed through as it is (`start => start`) binds itself again.
        $(#[allow(clippy::redundant_locals)]
        let $field = $tokens;)*
        let rt = $rt;
        quote! {
            #rt::boot::$ty {
                $($field: #$field,)*
            }
        }
    }};
}

fn network(plan: &NetworkPlan, rt: &TokenStream) -> TokenStream {
    boot_struct!(rt, plan, NetworkPlan {
        master => master_plan(master, rt),
        slaves => borrowed(slaves.iter().map(|s| slave(s, rt))),
        boot_time => option(boot_time.map(duration)),
        response_time => duration(*response_time),
        start_nodes => start_nodes,
        start_all_nodes => start_all_nodes,
        start_master => start_master,
        reset_all_nodes => reset_all_nodes,
        stop_all_nodes => stop_all_nodes,
        receive => borrowed(receive.iter().map(|l| link(l, rt))),
        transmit => borrowed(transmit.iter().map(|l| link(l, rt))),
    })
}

fn master_plan(master: &MasterPlan, rt: &TokenStream) -> TokenStream {
    boot_struct!(rt, master, MasterPlan {
        node => node_id(*node),
        heartbeat => option(heartbeat.map(duration)),
        sync_period => option(sync_period.map(duration)),
        sync_overflow => Literal::u8_unsuffixed(*sync_overflow),
    })
}

fn slave(slave: &SlaveConfig, rt: &TokenStream) -> TokenStream {
    boot_struct!(rt, slave, SlaveConfig {
        name => {
            let name: &str = name;
            quote!(alloc::borrow::Cow::Borrowed(#name))
        },
        plan => slave_plan(plan, rt),
        boot => boot,
        mandatory => mandatory,
        supervision => supervision_of(supervision, rt),
    })
}

fn supervision_of(supervision: &Supervision, rt: &TokenStream) -> TokenStream {
    match supervision {
        Supervision::None => quote!(#rt::boot::Supervision::None),
        Supervision::Heartbeat(time) => {
            let time = duration(*time);
            quote!(#rt::boot::Supervision::Heartbeat(#time))
        }
        Supervision::Guarding {
            guard_time,
            life_time_factor,
        } => {
            let guard_time = duration(*guard_time);
            let factor = Literal::u8_unsuffixed(life_time_factor.get());
            quote! {
                #rt::boot::Supervision::Guarding {
                    guard_time: #guard_time,
                    life_time_factor: match ::core::num::NonZeroU8::new(#factor) {
                        ::core::option::Option::Some(factor) => factor,
                        ::core::option::Option::None => panic!("a life time factor is 1 to 255"),
                    },
                }
            }
        }
    }
}

fn slave_plan(plan: &SlavePlan, rt: &TokenStream) -> TokenStream {
    boot_struct!(rt, plan, SlavePlan {
        node => node_id(*node),
        device_type => hex(*device_type),
        vendor_id => hex(*vendor_id),
        product_code => hex(*product_code),
        revision_number => hex(*revision_number),
        serial_number => hex(*serial_number),
        software_version => hex(*software_version),
        configuration_date_time => option(configuration_date_time.map(|(date, time)| {
            let (date, time) = (hex(date), hex(time));
            quote!((#date, #time))
        })),
        configuration => borrowed(configuration.iter().map(write)),
        reset => option(reset.map(|cmd| {
            let cmd = nmt_command(cmd);
            quote!(#rt::nmt::NmtCommand::#cmd)
        })),
        heartbeat => heartbeat,
        start => start,
    })
}

fn write(write: &ConfigWrite) -> TokenStream {
    let ConfigWrite {
        index,
        sub_index,
        data,
    } = write;
    let index = hex(u32::from(*index));
    let sub_index = Literal::u8_unsuffixed(*sub_index);
    let data = data.iter().map(|b| byte(*b));
    quote!(write(#index, #sub_index, &[#(#data),*]))
}

fn link(link: &PdoLink, rt: &TokenStream) -> TokenStream {
    boot_struct!(rt, link, PdoLink {
        node => node_id(*node),
        number => Literal::u16_unsuffixed(*number),
        cob_id => hex(*cob_id),
        transmission => Literal::u8_unsuffixed(*transmission),
        len => Literal::u8_unsuffixed(*len),
        event_timer => Literal::u16_unsuffixed(*event_timer),
        inhibit_time => Literal::u16_unsuffixed(*inhibit_time),
    })
}

/// The variant name of `cmd` (every command a plan may hold).
fn nmt_command(cmd: NmtCommand) -> TokenStream {
    match cmd {
        NmtCommand::Start => quote!(Start),
        NmtCommand::Stop => quote!(Stop),
        NmtCommand::EnterPreOperational => quote!(EnterPreOperational),
        NmtCommand::ResetNode => quote!(ResetNode),
        NmtCommand::ResetCommunication => quote!(ResetCommunication),
    }
}

/// A node id through the `network` module's `node_id` (a const check).
fn node_id(node: NodeId) -> TokenStream {
    let id = Literal::u8_unsuffixed(node.get());
    quote!(node_id(#id))
}

/// A duration in its largest whole unit.
fn duration(d: Duration) -> TokenStream {
    let nanos = d.as_nanos();
    let (unit, value) = if nanos.is_multiple_of(1_000_000_000) {
        (quote!(from_secs), nanos / 1_000_000_000)
    } else if nanos.is_multiple_of(1_000_000) {
        (quote!(from_millis), nanos / 1_000_000)
    } else if nanos.is_multiple_of(1_000) {
        (quote!(from_micros), nanos / 1_000)
    } else {
        (quote!(from_nanos), nanos)
    };
    // Every unit takes a u64; a plan's durations are far below its limit.
    let value = Literal::u64_unsuffixed(u64::try_from(value).unwrap_or(u64::MAX));
    quote!(::core::time::Duration::#unit(#value))
}

fn option(value: Option<TokenStream>) -> TokenStream {
    match value {
        Some(v) => quote!(::core::option::Option::Some(#v)),
        None => quote!(::core::option::Option::None),
    }
}

/// A byte as two hex digits (`0x0F`).
fn byte(b: u8) -> TokenStream {
    format!("0x{b:02X}")
        .parse()
        .unwrap_or_else(|_| Literal::u8_unsuffixed(b).into_token_stream())
}

fn hex(v: u32) -> TokenStream {
    prim::hex(u128::from(v))
}

/// `Cow::Borrowed(&[..])` of `items`.
fn borrowed(items: impl Iterator<Item = TokenStream>) -> TokenStream {
    let items: Vec<_> = items.collect();
    quote!(alloc::borrow::Cow::Borrowed(&[#(#items),*]))
}

/// A plan of master node 1 with `slaves` and nothing else, for tests.
#[cfg(test)]
pub(crate) fn test_plan(slaves: Vec<SlaveConfig>) -> NetworkPlan {
    NetworkPlan {
        master: MasterPlan {
            node: NodeId::new(1).expect("a node id"),
            heartbeat: None,
            sync_period: None,
            sync_overflow: 0,
        },
        slaves: slaves.into(),
        boot_time: None,
        response_time: NetworkPlan::DEFAULT_RESPONSE_TIME,
        start_nodes: true,
        start_all_nodes: false,
        start_master: true,
        reset_all_nodes: false,
        stop_all_nodes: false,
        receive: Vec::new().into(),
        transmit: Vec::new().into(),
    }
}

#[cfg(test)]
mod tests {
    use std::num::NonZeroU8;

    use super::*;

    fn text(tokens: TokenStream) -> String {
        tokens.to_string().replace(' ', "")
    }

    #[test]
    fn durations_take_their_largest_whole_unit() {
        let cases = [
            (
                Duration::from_secs(2),
                "::core::time::Duration::from_secs(2)",
            ),
            (
                Duration::from_millis(300),
                "::core::time::Duration::from_millis(300)",
            ),
            (
                Duration::from_micros(1500),
                "::core::time::Duration::from_micros(1500)",
            ),
            (
                Duration::from_nanos(7),
                "::core::time::Duration::from_nanos(7)",
            ),
            (Duration::ZERO, "::core::time::Duration::from_secs(0)"),
        ];
        for (d, expected) in cases {
            assert_eq!(text(duration(d)), expected, "{d:?}");
        }
    }

    #[test]
    fn a_guarded_slave_without_configuration_needs_no_write_helper() {
        let node = NodeId::new(3).expect("a node id");
        let mut plan = test_plan(vec![SlaveConfig {
            name: "drive".into(),
            plan: SlavePlan {
                node,
                device_type: 0x0002_0192,
                vendor_id: 0,
                product_code: 0,
                revision_number: 0,
                serial_number: 0,
                software_version: 0,
                configuration_date_time: Some((1, 2)),
                configuration: Vec::new().into(),
                reset: Some(NmtCommand::ResetNode),
                heartbeat: false,
                start: false,
            },
            boot: true,
            mandatory: true,
            supervision: Supervision::Guarding {
                guard_time: Duration::from_millis(100),
                life_time_factor: NonZeroU8::new(3).expect("not zero"),
            },
        }]);
        plan.boot_time = Some(Duration::from_secs(5));
        plan.start_all_nodes = true;
        plan.stop_all_nodes = true;
        let code = text(plan_const(&plan, &quote!(rt)));
        assert!(!code.contains("constfnwrite"), "{code}");
        assert!(
            code.contains("life_time_factor:match::core::num::NonZeroU8::new(3)"),
            "{code}"
        );
        assert!(
            code.contains("reset:::core::option::Option::Some(rt::nmt::NmtCommand::ResetNode)"),
            "{code}"
        );
        assert!(
            code.contains("configuration_date_time:::core::option::Option::Some((0x1,0x2))"),
            "{code}"
        );
        assert!(code.contains("device_type:0x020192"), "{code}");
    }
}
