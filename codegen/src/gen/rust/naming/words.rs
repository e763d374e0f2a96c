//! Word breaks that case conversion cannot guess: heck splits an uppercase
//! run before its last letter when lowercase follows (`PDOMapping` →
//! `pdo_mapping`), which is wrong for brand words (`CANopen` →
//! `ca_nopen`), plural acronyms (`PDOs` → `pd_os`), acronyms followed by a
//! lowercase word (`RPMact`) and units (`mV` → `m_v`). [`mark_words`]
//! rewrites such words in lowercase, with a space where a word starts, so
//! that heck then splits the text right. Text without them is unchanged.

/// Mixed-case words written as one word: brand names and the like.
const WORDS: &[&str] = &["CANopen", "CiA", "IPv4", "IPv6", "MHz", "GHz"];

/// Acronyms that may be followed by a lowercase word without a break
/// (`CANdaemon`, `RPMact`, `TPDOmapping`).
const ACRONYMS: &[&str] = &[
    "CAN", "COB", "CRC", "DCF", "EDS", "EMCY", "LSS", "MPDO", "NMT", "PDO", "RPDO", "RPM", "SDO",
    "SYNC", "TPDO",
];

/// SI prefixes of a unit written as one token (`mV`, `kW`, `hPa`, `mHz`).
const UNIT_PREFIXES: &[u8] = b"munpkhd";

/// `text` (ASCII letters, digits and spaces) with the words above lowercased
/// and set apart; see the module documentation.
pub(super) fn mark_words(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 8);
    for (i, token) in text.split(' ').enumerate() {
        if i > 0 {
            out.push(' ');
        }
        mark_token(token, &mut out);
    }
    out
}

/// One alphanumeric token.
fn mark_token(token: &str, out: &mut String) {
    let b = token.as_bytes();
    if is_unit(b) {
        out.push_str(&token.to_ascii_lowercase());
        return;
    }
    let mut i = 0;
    while i < b.len() {
        // A word may start at the token's start or where heck starts one
        // (after a lowercase letter or a digit); not inside an uppercase run.
        let at_start = i == 0 || !b[i - 1].is_ascii_uppercase();
        if let Some(len) = word_at(&b[i..]).filter(|_| at_start && b[i].is_ascii_uppercase()) {
            if i > 0 {
                out.push(' ');
            }
            out.push_str(&token[i..i + len].to_ascii_lowercase());
            // A following lowercase word needs its own break.
            if b.get(i + len).is_some_and(u8::is_ascii_lowercase) {
                out.push(' ');
            }
            i += len;
            continue;
        }
        out.push(b[i] as char);
        i += 1;
    }
}

/// The length of a word of this module's rules at the start of `b`.
fn word_at(b: &[u8]) -> Option<usize> {
    let next_lower = |len: usize| b.get(len).is_some_and(u8::is_ascii_lowercase);
    for word in WORDS {
        if b.starts_with(word.as_bytes()) && !next_lower(word.len()) {
            return Some(word.len());
        }
    }
    let run = b.iter().take_while(|c| c.is_ascii_uppercase()).count();
    if run < 2 || !next_lower(run) {
        return None;
    }
    // A plural acronym: `PDOs`, `IDs`, `LEDs`.
    if b[run] == b's' && !next_lower(run + 1) {
        return Some(run + 1);
    }
    // A known acronym followed by a lowercase word: `CANdaemon`.
    let known = |w: &[u8]| ACRONYMS.iter().any(|a| a.as_bytes() == w);
    if known(&b[..run]) && !known(&b[..run - 1]) {
        return Some(run);
    }
    None
}

/// A unit written as one token: an SI prefix, an uppercase letter and at
/// most one lowercase letter (`mV`, `kW`, `hPa`, `kHz`).
fn is_unit(b: &[u8]) -> bool {
    matches!(b, [p, u, rest @ ..]
        if UNIT_PREFIXES.contains(p)
            && u.is_ascii_uppercase()
            && rest.len() <= 1
            && rest.iter().all(u8::is_ascii_lowercase))
}

#[cfg(test)]
mod tests {
    use super::super::{Case, sanitize};

    fn snake(text: &str) -> String {
        sanitize(text, Case::Snake)
    }

    #[test]
    fn brand_words_are_one_word() {
        assert_eq!(snake("CANopen settings"), "canopen_settings");
        assert_eq!(
            sanitize("CANopen settings", Case::UpperCamel),
            "CanopenSettings"
        );
        assert_eq!(
            sanitize("CANopen settings", Case::ShoutySnake),
            "CANOPEN_SETTINGS"
        );
        assert_eq!(snake("CANopenNode"), "canopen_node");
        assert_eq!(snake("Use CANopen"), "use_canopen");
        assert_eq!(snake("CiA 402 mode"), "cia_402_mode");
        assert_eq!(snake("CiA402"), "cia402");
        assert_eq!(snake("IPv4 address"), "ipv4_address");
        assert_eq!(snake("Clock MHz"), "clock_mhz");
    }

    #[test]
    fn acronyms_split_where_they_end() {
        assert_eq!(snake("RPDO1 mapping"), "rpdo1_mapping");
        assert_eq!(snake("TPDO communication"), "tpdo_communication");
        assert_eq!(snake("COB-ID SYNC"), "cob_id_sync");
        assert_eq!(snake("NMT startup"), "nmt_startup");
        assert_eq!(snake("NMTStartup"), "nmt_startup");
        assert_eq!(snake("PDOMapping"), "pdo_mapping");
        assert_eq!(snake("EMCY inhibit"), "emcy_inhibit");
        assert_eq!(snake("LSS address"), "lss_address");
        assert_eq!(snake("EDS file DCF"), "eds_file_dcf");
        assert_eq!(snake("SDO server"), "sdo_server");
        assert_eq!(snake("CANdaemon"), "can_daemon");
        assert_eq!(snake("RPMact"), "rpm_act");
        assert_eq!(sanitize("RPMact", Case::UpperCamel), "RpmAct");
        assert_eq!(snake("TxPDO1"), "tx_pdo1");
    }

    #[test]
    fn plural_acronyms_keep_their_s() {
        assert_eq!(snake("Number of PDOs"), "number_of_pdos");
        assert_eq!(snake("MPDOs"), "mpdos");
        assert_eq!(snake("SSPs"), "ssps");
        assert_eq!(snake("maxIDs"), "max_ids");
        assert_eq!(
            sanitize("Supported SDOs", Case::UpperCamel),
            "SupportedSdos"
        );
    }

    #[test]
    fn units_are_one_word() {
        assert_eq!(snake("Voltage mV"), "voltage_mv");
        assert_eq!(snake("Current (mA)"), "current_ma");
        assert_eq!(snake("Pressure hPa"), "pressure_hpa");
        assert_eq!(snake("Rate kHz"), "rate_khz");
        // Not units: longer tokens, other letters.
        assert_eq!(snake("subA"), "sub_a");
        assert_eq!(snake("xPos"), "x_pos");
    }

    #[test]
    fn other_names_split_as_before() {
        assert_eq!(snake("VCell1"), "v_cell1");
        assert_eq!(snake("NodeID"), "node_id");
        assert_eq!(snake("microSteps"), "micro_steps");
        assert_eq!(snake("DOut"), "d_out");
        assert_eq!(snake("NanoJ control"), "nano_j_control");
        assert_eq!(snake("Motor-Temperatur (°C)"), "motor_temperatur_c");
        assert_eq!(
            sanitize("RpdoCommunicationParameter", Case::UpperCamel),
            "RpdoCommunicationParameter"
        );
    }
}
