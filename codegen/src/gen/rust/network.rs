//! A network's top file: one module per node (its generated file included
//! beside it) and the `network` module: the nodes with their ids and
//! identities, the master's process image (the slaves' TPDOs it receives,
//! the slaves' RPDOs it sends, as fields of the nodes' PDO structs) and the
//! timing constants.
//!
//! It takes plain data ([`Network`]): what the bus file and the configured
//! network say, and the PDO structs each node's generation made. It knows
//! nothing of the bus file's syntax.

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use eds2rust_runtime::boot::NetworkPlan;

use super::docs::{self, Doc};
use super::naming::{self, Case, Namespace};
use super::pdo::Emitted;
use super::{HEADER, RUNTIME_ALIAS, derives, format, network_plan, prim};
use crate::diag::Diagnostics;
use crate::ir::{Origin, PdoDirection};

/// A network to generate.
pub(crate) struct Network<'a> {
    /// The bus file as shown in the header.
    pub(crate) source: &'a str,
    /// The folder, beside the top file, holding the nodes' files
    /// (`<dir>/<module>.rs`).
    pub(crate) dir: &'a str,
    pub(crate) master: Master,
    pub(crate) nodes: Vec<NodeInput<'a>>,
    /// The network's boot plan (`network::boot_plan`), embedded as
    /// `network::PLAN`.
    pub(crate) plan: &'a NetworkPlan,
}

/// The master's settings the generated constants show.
pub(crate) struct Master {
    /// 255: not configured.
    pub(crate) node_id: u8,
    pub(crate) bit_rate_kbit: u32,
    pub(crate) sync_period_us: u32,
    pub(crate) sync_window_us: u32,
    pub(crate) heartbeat_producer_ms: u16,
}

/// One node.
pub(crate) struct NodeInput<'a> {
    /// Its YAML key.
    pub(crate) name: &'a str,
    /// Its module name ([`module_names`]).
    pub(crate) module: String,
    pub(crate) node_id: u8,
    pub(crate) vendor_id: u32,
    pub(crate) product_code: u32,
    pub(crate) revision_number: u32,
    pub(crate) serial_number: u32,
    pub(crate) heartbeat_producer_ms: u16,
    pub(crate) product_name: Option<&'a str>,
    /// The device file as shown.
    pub(crate) device_file: String,
    /// The node's configured PDOs, each with its generated struct.
    pub(crate) pdos: Vec<NodePdo>,
}

/// A configured PDO of a node and its struct in the node's `pdo` module.
pub(crate) struct NodePdo {
    pub(crate) pdo: Emitted,
    pub(crate) cob_id: u32,
    pub(crate) transmission: u8,
}

/// The module name of every node (in order): its YAML key as a snake_case
/// identifier under the naming rules of every generated name (keys that
/// become equal are both qualified with their node id and reported).
/// `network` is taken by the network module.
pub(crate) fn module_names(nodes: &[(&str, u8, Origin)], diags: &mut Diagnostics) -> Vec<String> {
    let mut ns = Namespace::new("the network's modules", Case::Snake);
    ns.reserve("network");
    let ids: Vec<_> = nodes
        .iter()
        .map(|(name, id, origin)| ns.request(name, &format!("node {id}"), Some(origin)))
        .collect();
    let names = ns.resolve(diags);
    ids.into_iter()
        .map(|id| names.text(id).to_string())
        .collect()
}

/// The formatted top file.
pub(crate) fn generate(network: &Network, runtime: &TokenStream) -> syn::Result<String> {
    let rt = naming::ident(RUNTIME_ALIAS);
    let rt = quote!(#rt);
    let mut items = TokenStream::new();
    for node in &network.nodes {
        let module = naming::ident(&node.module);
        let path = format!("{}/{}.rs", network.dir, node.module);
        let mut doc = Doc::new();
        let product = node
            .product_name
            .map(|p| format!(", {}", docs::text(p)))
            .unwrap_or_default();
        doc.para(format!(
            "**{}**: node {}{product}, from `{}`.",
            docs::text(node.name),
            node.node_id,
            docs::text(&node.device_file)
        ));
        doc.para(
            "Its object dictionary as the device file gives it; `pdo` holds the PDOs the network configures.",
        );
        let doc = doc.tokens();
        let id = Literal::u8_unsuffixed(node.node_id);
        items.extend(quote! {
            #doc
            pub mod #module {
                include!(#path);
                #[doc = " This node's id on the network."]
                pub const NODE_ID: u8 = #id;
            }
        });
    }
    items.extend(network_module(network, runtime, &rt));
    let code = format::file(items)?;
    let source = network.source.replace(['\n', '\r'], " ");
    let code = format!("{HEADER} {source}; do not edit.\n\n{code}");
    Ok(crate::text::code(&code).into_owned())
}

fn network_module(network: &Network, runtime: &TokenStream, rt: &TokenStream) -> TokenStream {
    let m = &network.master;
    let hex = |v: u32| prim::hex(u128::from(v));
    let bit_rate = Literal::u32_unsuffixed(m.bit_rate_kbit);
    let sync_period = Literal::u32_unsuffixed(m.sync_period_us);
    let sync_window = Literal::u32_unsuffixed(m.sync_window_us);
    let heartbeat = Literal::u16_unsuffixed(m.heartbeat_producer_ms);
    let master_id = Literal::u8_unsuffixed(m.node_id);
    let mut node_consts = Vec::new();
    let mut node_names = Vec::new();
    for node in &network.nodes {
        let ident = naming::ident(&node.module.to_ascii_uppercase());
        let name = node.name;
        let id = Literal::u8_unsuffixed(node.node_id);
        let (vendor, product, revision, serial) = (
            hex(node.vendor_id),
            hex(node.product_code),
            hex(node.revision_number),
            hex(node.serial_number),
        );
        let hb = Literal::u16_unsuffixed(node.heartbeat_producer_ms);
        let doc = format!(" **{}**, node {}.", docs::text(node.name), node.node_id);
        node_consts.push(quote! {
            #[doc = #doc]
            pub const #ident: super::Node = super::Node {
                name: #name,
                node_id: super::node_id(#id),
                vendor_id: #vendor,
                product_code: #product,
                revision_number: #revision,
                serial_number: #serial,
                heartbeat_producer_ms: #hb,
            };
        });
        node_names.push(quote!(nodes::#ident));
    }
    let count = Literal::usize_unsuffixed(network.nodes.len());
    let inputs = image(network, PdoDirection::Tpdo, rt);
    let outputs = image(network, PdoDirection::Rpdo, rt);
    let plan = network_plan::plan_const(network.plan, rt);
    quote! {
        #[doc = " The network: its nodes, its boot plan, the master's process image and its timing (with the runtime's `alloc` feature, as the master)."]
        pub mod network {
            extern crate alloc;
            use #runtime as #rt;
            #[doc = " The bit rate, kbit/s (`master.baudrate`)."]
            pub const BIT_RATE_KBIT: u32 = #bit_rate;
            #[doc = " The master's node id (`master.node_id`; 255: not configured)."]
            pub const MASTER_NODE_ID: u8 = #master_id;
            #[doc = " The SYNC period, µs (`master.sync_period`; 0: the master sends no SYNC)."]
            pub const SYNC_PERIOD_US: u32 = #sync_period;
            #[doc = " The synchronous window, µs (`master.sync_window`; 0: none)."]
            pub const SYNC_WINDOW_US: u32 = #sync_window;
            #[doc = " The master's heartbeat producer time, ms (`master.heartbeat_producer`; 0: none)."]
            pub const MASTER_HEARTBEAT_MS: u16 = #heartbeat;
            #[doc = " A node of the network, as the bus file and its device file describe it."]
            #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
            pub struct Node {
                #[doc = " Its name in the bus file."]
                pub name: &'static str,
                pub node_id: #rt::od::NodeId,
                #[doc = " 0x1018 sub 1 (0: not given, not checked at boot)."]
                pub vendor_id: u32,
                #[doc = " 0x1018 sub 2 (0: not given, not checked at boot)."]
                pub product_code: u32,
                #[doc = " 0x1018 sub 3 (0: not given, not checked at boot)."]
                pub revision_number: u32,
                #[doc = " 0x1018 sub 4 (0: not given, not checked at boot)."]
                pub serial_number: u32,
                #[doc = " Heartbeat producer time, ms (0: none)."]
                pub heartbeat_producer_ms: u16,
            }
            #[doc = " Every node, one constant each."]
            pub mod nodes {
                #(#node_consts)*
            }
            #[doc = " Every node, in the bus file's order."]
            pub const NODES: [Node; #count] = [#(#node_names),*];
            const fn node_id(id: u8) -> #rt::od::NodeId {
                match #rt::od::NodeId::new(id) {
                    ::core::option::Option::Some(id) => id,
                    ::core::option::Option::None => panic!("a node id is 1 to 127"),
                }
            }
            #plan
            #inputs
            #outputs
        }
    }
}

/// The master's inputs (the slaves' TPDOs) or outputs (their RPDOs).
fn image(network: &Network, direction: PdoDirection, rt: &TokenStream) -> TokenStream {
    let mut fields = Vec::new();
    let mut float = false;
    for node in &network.nodes {
        let module = naming::ident(&node.module);
        for p in node.pdos.iter().filter(|p| p.pdo.direction == direction) {
            let kind = match direction {
                PdoDirection::Rpdo => "rpdo",
                PdoDirection::Tpdo => "tpdo",
            };
            let field = naming::ident(&format!("{}_{kind}{}", node.module, p.pdo.number));
            let ty = naming::ident(&p.pdo.ident);
            let when = match p.transmission {
                0 => "acyclic synchronous (after a SYNC, when it changed)".to_string(),
                1 => "each SYNC".to_string(),
                n @ 2..=240 => format!("each {n}th SYNC"),
                252 | 253 => "on request (RTR)".to_string(),
                n => format!("event-driven (transmission type {n})"),
            };
            let doc = format!(
                " **{}** {}{}, COB-ID 0x{:X}, {} bytes: {when}.",
                docs::text(node.name),
                kind.to_uppercase(),
                p.pdo.number,
                p.cob_id,
                p.pdo.len
            );
            let can_id = if p.cob_id > 0x7FF {
                let id = prim::hex(u128::from(p.cob_id));
                quote!(#rt::CanId::Extended(#id))
            } else {
                let id = prim::hex(u128::from(p.cob_id));
                quote!(#rt::CanId::Standard(#id))
            };
            float |= p.pdo.float;
            fields.push((field, quote!(super::#module::pdo::#ty), doc, can_id));
        }
    }
    let names: Vec<_> = fields.iter().map(|f| &f.0).collect();
    let count = Literal::usize_unsuffixed(fields.len());
    match direction {
        PdoDirection::Tpdo => {
            let defs = fields
                .iter()
                .map(|(f, ty, doc, _)| quote!(#[doc = #doc] pub #f: ::core::option::Option<#ty>));
            // Two inputs on one identifier (a collision `net check`
            // reports): the first takes the frame.
            let mut ids = std::collections::BTreeSet::new();
            let arms =
                fields
                    .iter()
                    .filter(|f| ids.insert(f.3.to_string()))
                    .map(|(f, ty, _, id)| {
                        quote! {
                            #id => {
                                self.#f = ::core::option::Option::Some(#ty::decode(frame.data())?);
                                ::core::result::Result::Ok(true)
                            }
                        }
                    });
            // Without inputs the match has one arm.
            let allow = fields
                .is_empty()
                .then(|| quote!(#[allow(clippy::match_single_binding)]));
            // The receiver keeps one slot per identifier: the first input
            // on it takes it, as in `receive`.
            let mut ids = std::collections::BTreeSet::new();
            let latest = fields.iter().filter(|f| ids.insert(f.3.to_string())).map(
                |(f, ty, _, _)| {
                    quote! {
                        if let ::core::option::Option::Some(pdo) = rx.latest::<#ty>(#ty::CAN_ID) {
                            self.#f = ::core::option::Option::Some(pdo?);
                        }
                    }
                },
            );
            let rx_unused = fields.is_empty().then(|| quote!(let _ = rx;));
            let mut derive_list = derives::names(derives::PDO, float);
            derive_list.push("Default");
            let derive_idents = derive_list.iter().map(|d| naming::ident(d));
            quote! {
                #[doc = " What the master receives: each slave TPDO as last received (`None` before the first)."]
                #[derive(#(#derive_idents),*)]
                pub struct Inputs {
                    #(#defs,)*
                }
                impl Inputs {
                    #[doc = " The number of PDOs received."]
                    pub const LEN: usize = #count;
                    #[doc = " Nothing received yet."]
                    pub const fn new() -> Self {
                        Self { #(#names: ::core::option::Option::None,)* }
                    }
                    #[doc = " Takes a received frame: decoded into its field when its identifier is an input's (`Ok(true)`), ignored otherwise (`Ok(false)`, remote frames too); a length that is not the PDO's is an error and the field keeps its value. Never panics."]
                    pub fn receive(&mut self, frame: &#rt::Frame) -> ::core::result::Result<bool, #rt::od::PdoLengthError> {
                        if frame.is_remote() {
                            return ::core::result::Result::Ok(false);
                        }
                        #allow
                        match frame.id() {
                            #(#arms)*
                            _ => ::core::result::Result::Ok(false),
                        }
                    }
                    #[doc = " Takes the last data the master's PDO receiver holds for each input (`master.pdo_rx` of a `Master::for_network(&PLAN)`, which watches every input): a field is updated once its PDO was received; the others keep their value. A length that is not the PDO's is an error. Never panics."]
                    pub fn take_latest<const N: usize>(&mut self, rx: &#rt::pdo::PdoReceiver<N>) -> ::core::result::Result<(), #rt::od::PdoLengthError> {
                        #rx_unused
                        #(#latest)*
                        ::core::result::Result::Ok(())
                    }
                }
            }
        }
        PdoDirection::Rpdo => {
            let defs = fields
                .iter()
                .map(|(f, ty, doc, _)| quote!(#[doc = #doc] pub #f: #ty));
            let frames = fields.iter().map(|(f, _, _, id)| {
                quote! {{
                    let mut data = [0u8; 8];
                    let len = #rt::od::Pdo::encode_into(&self.#f, &mut data);
                    #rt::Frame::with_id(#id, data, len as u8)
                }}
            });
            let sets = fields
                .iter()
                .map(|(f, ty, _, _)| quote!(master.set_pdo(now, #ty::COB_ID, &self.#f)?;));
            let unused = fields.is_empty().then(|| quote!(let _ = (master, now);));
            let derives = derives::attr(derives::PDO, float);
            quote! {
                #[doc = " What the master sends: each slave RPDO."]
                #derives
                pub struct Outputs {
                    #(#defs,)*
                }
                impl Outputs {
                    #[doc = " The number of PDOs sent."]
                    pub const LEN: usize = #count;
                    #[doc = " The frames of every output, in the order of the fields."]
                    pub fn frames(&self) -> [#rt::Frame; #count] {
                        [#(#frames),*]
                    }
                    #[doc = " Sets every output as the data of its RPDO on the master (`Master::set_pdo` with the PDO's COB-ID; `Master::for_network(&PLAN)` set up each one's transmitter): a synchronous one goes out after the next SYNC, an event-driven one at once (after its inhibit time)."]
                    pub fn set_pdos(&self, master: &mut #rt::master::Master, now: #rt::Instant) -> ::core::result::Result<(), #rt::pdo::PdoError> {
                        #unused
                        #(#sets)*
                        ::core::result::Result::Ok(())
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn module_names_follow_the_naming_rules() {
        let origin = Origin {
            file: "bus.yml".into(),
            line: 3,
        };
        let nodes = [
            ("Zimmer Axis", 40, origin.clone()),
            ("network", 2, origin.clone()),
            ("type", 3, origin.clone()),
            ("axis-1", 4, origin.clone()),
            ("axis_1", 5, origin.clone()),
        ];
        let mut diags = Diagnostics::new();
        let names = module_names(&nodes, &mut diags);
        assert_eq!(
            names,
            [
                "zimmer_axis",
                "network_node_2",
                "type_",
                "axis_1_node_4",
                "axis_1_node_5"
            ]
        );
        assert!(diags.iter().any(|d| d.code == "gen::name-collision"));
    }

    fn input(name: &str, pdos: Vec<NodePdo>) -> NodeInput<'_> {
        NodeInput {
            name,
            module: name.into(),
            node_id: 2,
            vendor_id: 0,
            product_code: 0,
            revision_number: 0,
            serial_number: 0,
            heartbeat_producer_ms: 0,
            product_name: None,
            device_file: "d.eds".into(),
            pdos,
        }
    }

    fn tpdo(number: u16, cob_id: u32) -> NodePdo {
        NodePdo {
            pdo: Emitted {
                direction: PdoDirection::Tpdo,
                number,
                ident: format!("Tpdo{number}"),
                len: 2,
                float: false,
            },
            cob_id,
            transmission: 1,
        }
    }

    fn network(nodes: Vec<NodeInput<'_>>) -> String {
        let plan = super::network_plan::test_plan(Vec::new());
        let network = Network {
            source: "bus.yml",
            dir: "net",
            master: Master {
                node_id: 1,
                bit_rate_kbit: 500,
                sync_period_us: 0,
                sync_window_us: 0,
                heartbeat_producer_ms: 0,
            },
            nodes,
            plan: &plan,
        };
        generate(&network, &quote!(::eds2rust_runtime)).expect("valid Rust")
    }

    #[test]
    fn an_empty_network_is_valid_rust() {
        let code = network(Vec::new());
        assert!(code.contains("pub const NODES: [Node; 0] = [];"), "{code}");
        assert!(
            code.contains("pub fn frames(&self) -> [rt::Frame; 0]"),
            "{code}"
        );
        assert!(code.contains("clippy::match_single_binding"), "{code}");
    }

    #[test]
    fn two_inputs_on_one_identifier_give_one_arm() {
        let code = network(vec![input("a", vec![tpdo(1, 0x182), tpdo(2, 0x182)])]);
        assert_eq!(
            code.matches("rt::CanId::Standard(0x182) =>").count(),
            1,
            "{code}"
        );
        assert!(code.contains("pub a_tpdo2:"), "{code}");
        assert!(!code.contains("clippy::match_single_binding"), "{code}");
    }
}
