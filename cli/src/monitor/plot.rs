//! `eds2rust monitor --plot FIELD...`: the values of named PDO fields over
//! time, charted as SVG when the monitor ends (plotters, SVG backend).
//!
//! A value is the field's physical value when its entry has a scale or an
//! offset (or is a REAL), else its raw value; it holds until the next frame
//! of its PDO, so every line is drawn as steps, up to the end of the run.

use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::sync::Arc;

use eds2rust_decode::pdo::Raw;
use eds2rust_decode::{Kind, Record};
use plotters::prelude::*;

/// The size of the chart in pixels.
const SIZE: (u32, u32) = (1000, 560);

/// One `--plot` argument: a field name as the decoder gives it
/// (`Feedback.Position`), of any node or only of `node` (`32:...`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotSpec {
    pub node: Option<u8>,
    pub field: String,
}

impl fmt::Display for PlotSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.node {
            Some(n) => write!(f, "{n}:{}", self.field),
            None => f.write_str(&self.field),
        }
    }
}

/// `NAME` or `N:NAME` (N a node id, 1 to 127).
pub fn parse_spec(text: &str) -> Result<PlotSpec, String> {
    let text = text.trim();
    if let Some((n, field)) = text.split_once(':')
        && !n.is_empty()
        && n.bytes().all(|b| b.is_ascii_digit())
    {
        let node = n
            .parse::<u8>()
            .ok()
            .filter(|n| (1..=127).contains(n))
            .ok_or_else(|| format!("`{n}` in `{text}` is not a node id (1 to 127)"))?;
        let field = field.trim();
        if field.is_empty() {
            return Err(format!("no field name after `{n}:`"));
        }
        return Ok(PlotSpec {
            node: Some(node),
            field: field.to_string(),
        });
    }
    if text.is_empty() {
        return Err("an empty field name (for example Feedback.Position)".into());
    }
    Ok(PlotSpec {
        node: None,
        field: text.to_string(),
    })
}

/// The values of one field of one node.
#[derive(Debug, Clone)]
pub struct Series {
    pub node: u8,
    pub field: Arc<str>,
    pub unit: Option<String>,
    /// (seconds since the monitor started, value), in time order.
    pub points: Vec<(f64, f64)>,
}

impl Series {
    /// The legend entry: `32:Feedback.Position [mm]`.
    pub fn label(&self) -> String {
        match &self.unit {
            Some(u) => format!("{}:{} [{u}]", self.node, self.field),
            None => format!("{}:{}", self.node, self.field),
        }
    }

    /// The points of the step line up to `end`: each value held until the
    /// next one.
    pub fn steps(&self, end: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::with_capacity(self.points.len() * 2 + 1);
        for &(t, v) in &self.points {
            if let Some(&(_, held)) = out.last() {
                out.push((t, held));
            }
            out.push((t, v));
        }
        if let Some(&(t, v)) = out.last()
            && end > t
        {
            out.push((end, v));
        }
        out
    }
}

/// The fields asked for, their values, and every field name seen.
#[derive(Debug, Clone)]
pub struct Plot {
    specs: Vec<PlotSpec>,
    /// Which specs named a field that was seen.
    matched: Vec<bool>,
    pub series: Vec<Series>,
    /// (node, field) → its series, `None` when no spec names it.
    slots: HashMap<(u8, Arc<str>), Option<usize>>,
    /// The PDO field names of every node, in the order first seen.
    seen: BTreeMap<u8, Vec<Arc<str>>>,
}

impl Plot {
    pub fn new(specs: Vec<PlotSpec>) -> Plot {
        Plot {
            matched: vec![false; specs.len()],
            specs,
            series: Vec::new(),
            slots: HashMap::new(),
            seen: BTreeMap::new(),
        }
    }

    /// Takes one record of time `t` (seconds since the monitor started):
    /// the fields of a PDO.
    pub fn record(&mut self, t: f64, record: &Record) {
        let Record::Frame(f) = record else { return };
        let (Some(node), Kind::Pdo { .. }) = (f.node, &f.kind) else {
            return;
        };
        for field in f.kind.pdo_fields() {
            let key = (node, field.name.clone());
            let slot = match self.slots.get(&key) {
                Some(&slot) => slot,
                None => {
                    let slot = self.new_field(node, &field.name, field.unit.clone());
                    self.slots.insert(key, slot);
                    slot
                }
            };
            if let Some(i) = slot {
                let value = field.number.unwrap_or(match field.raw {
                    Raw::Int(v) => v as f64,
                    Raw::Real(v) => v,
                });
                self.series[i].points.push((t, value));
            }
        }
    }

    /// A field seen for the first time: its series, when a spec names it.
    fn new_field(&mut self, node: u8, name: &Arc<str>, unit: Option<String>) -> Option<usize> {
        self.seen.entry(node).or_default().push(name.clone());
        let mut wanted = false;
        for (spec, matched) in self.specs.iter().zip(&mut self.matched) {
            if *spec.field == **name && spec.node.is_none_or(|n| n == node) {
                *matched = true;
                wanted = true;
            }
        }
        wanted.then(|| {
            self.series.push(Series {
                node,
                field: name.clone(),
                unit,
                points: Vec::new(),
            });
            self.series.len() - 1
        })
    }

    /// What to tell about the specs that named no field seen; `None` when
    /// every one did.
    pub fn unknown(&self) -> Option<String> {
        let missing: Vec<&PlotSpec> = self
            .specs
            .iter()
            .zip(&self.matched)
            .filter(|(_, m)| !**m)
            .map(|(s, _)| s)
            .collect();
        if missing.is_empty() {
            return None;
        }
        let mut text = String::new();
        for spec in missing {
            let from = spec
                .node
                .map_or_else(String::new, |n| format!(" from node {n}"));
            text.push_str(&format!(
                "error: --plot {spec}: no PDO field of that name was seen{from}"
            ));
            if let Some(close) = self.closest(spec) {
                text.push_str(&format!("; did you mean `{close}`?"));
            }
            text.push('\n');
        }
        if self.seen.is_empty() {
            text.push_str(
                "fields seen: none (no PDO of a node given with --node N=FILE was received)\n",
            );
        } else {
            text.push_str("fields seen:\n");
            for (node, names) in &self.seen {
                let names: Vec<&str> = names.iter().map(|n| &**n).collect();
                text.push_str(&format!("  node {node}: {}\n", names.join(", ")));
            }
        }
        Some(text)
    }

    /// The seen name most like `spec`'s (of its node, if it names one).
    fn closest(&self, spec: &PlotSpec) -> Option<String> {
        let want = spec.field.to_lowercase();
        self.seen
            .iter()
            .filter(|(n, _)| spec.node.is_none_or(|s| s == **n))
            .flat_map(|(n, names)| names.iter().map(move |name| (*n, name)))
            .map(|(n, name)| (strsim::jaro_winkler(&want, &name.to_lowercase()), n, name))
            .filter(|(score, ..)| *score > 0.85)
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, n, name)| match spec.node {
                Some(_) => format!("{n}:{name}"),
                None => name.to_string(),
            })
    }

    /// The chart as SVG: one line per series up to `end` (seconds since
    /// the monitor started), a legend with names and units. `None` when no
    /// series has a value.
    pub fn svg(&self, end: f64) -> Option<Result<String, String>> {
        let series: Vec<&Series> = self
            .series
            .iter()
            .filter(|s| !s.points.is_empty())
            .collect();
        if series.is_empty() {
            return None;
        }
        Some(draw(&series, end).map_err(|e| e.to_string()))
    }
}

/// The value range with a margin; a flat line gets room around it.
fn value_range(series: &[&Series]) -> (f64, f64) {
    let values = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    let pad = if hi - lo > f64::EPSILON * hi.abs().max(1.0) {
        (hi - lo) * 0.05
    } else {
        (hi.abs() * 0.05).max(1.0)
    };
    // Room at the top for the legend, a line per series.
    let legend = pad * 1.2 * series.len() as f64;
    (lo - pad, hi + pad + legend)
}

fn draw(series: &[&Series], end: f64) -> Result<String, Box<dyn std::error::Error>> {
    let last = series
        .iter()
        .filter_map(|s| s.points.last().map(|p| p.0))
        .fold(0.0, f64::max);
    let end = end.max(last).max(0.1);
    let (lo, hi) = value_range(series);
    let unit = series[0].unit.as_deref();
    let y_desc = match unit {
        Some(u) if series.iter().all(|s| s.unit.as_deref() == Some(u)) => format!("value [{u}]"),
        _ => "value".to_string(),
    };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption("eds2rust monitor", ("sans-serif", 26))
            .margin(16)
            .x_label_area_size(44)
            .y_label_area_size(72)
            .build_cartesian_2d(0.0..end, lo..hi)?;
        chart
            .configure_mesh()
            .x_desc("time [s]")
            .y_desc(y_desc)
            .label_style(("sans-serif", 16))
            .axis_desc_style(("sans-serif", 18))
            .draw()?;
        for (i, s) in series.iter().enumerate() {
            let color = Palette99::pick(i).to_rgba();
            chart
                .draw_series(LineSeries::new(s.steps(end), color.stroke_width(2)))?
                .label(s.label())
                .legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 20, y)], color.stroke_width(2))
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 16))
            .draw()?;
        root.present()?;
    }
    Ok(svg)
}
