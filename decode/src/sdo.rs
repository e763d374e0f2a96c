//! SDO frames of one node's default channel, read with the runtime's SDO
//! frame parsers, and transfers (expedited, segmented, block; both
//! directions) reassembled from them. A trace may start in the middle of a
//! transfer: segments without their initiate frame are described but make
//! no transfer.

use eds2rust_runtime::sdo::AbortCode;
use eds2rust_runtime::sdo::proto::{BlockSegment, Initiate, Request, Response};

/// Who sent an SDO frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The client (requests, to the node: 0x600 + node).
    Client,
    /// The server (responses, from the node: 0x580 + node).
    Server,
}

/// What an SDO frame is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SdoFrame {
    Request(Request),
    Response(Response),
    /// A segment of a block download (client) or upload (server).
    BlockSegment(BlockSegment),
}

/// Direction of a transfer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    Upload,
    Download,
}

impl Direction {
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Upload => "upload",
            Direction::Download => "download",
        }
    }
}

/// A transfer that ended: with the data, or with an abort.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Transfer {
    pub index: u16,
    pub subindex: u8,
    pub direction: Direction,
    pub data: Vec<u8>,
    /// `None`: done; `Some(code)`: aborted with it.
    pub abort: Option<AbortCode>,
    /// How the data travelled: `expedited`, `segmented` or `block`.
    pub method: &'static str,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    /// The initiate request was seen; its response is awaited.
    Initiated,
    /// Segments (or blocks) are flowing.
    Data,
    /// Block transfers: the end frame is awaited (or, for a block download,
    /// seen and its confirmation awaited).
    End,
}

#[derive(Debug, Clone)]
struct Open {
    index: u16,
    subindex: u8,
    direction: Direction,
    method: &'static str,
    phase: Phase,
    data: Vec<u8>,
    /// Block transfers: the segments of the current block, until acknowledged.
    block: Vec<[u8; 7]>,
    /// Block transfers: the current block ended with the last segment.
    last_seen: bool,
    /// Unused bytes of the last segment of a block download (its end request).
    unused: u8,
}

/// The SDO state of one node's default channel.
#[derive(Debug, Default)]
pub struct SdoChannel {
    open: Option<Open>,
}

/// What a frame did to the channel's transfer.
#[derive(Debug, Default)]
pub struct Step {
    pub frame: Option<SdoFrame>,
    /// The frame is not a valid SDO frame: why.
    pub error: Option<String>,
    /// The index and sub the frame names (or the open transfer's).
    pub target: Option<(u16, u8)>,
    pub ended: Option<Transfer>,
    /// A note on the frame (a segment without its transfer, a toggle error).
    pub note: Option<&'static str>,
}

impl SdoChannel {
    /// Takes one frame of the channel (`role`: who sent it).
    pub fn frame(&mut self, role: Role, data: &[u8]) -> Step {
        let mut step = Step::default();
        let in_block_data = |dir| matches!(&self.open, Some(o) if o.method == "block" && o.direction == dir && o.phase == Phase::Data);
        // Block segments carry no command specifier: they are told by the
        // transfer they belong to (an abort is still an abort).
        let segment = match role {
            Role::Client => in_block_data(Direction::Download),
            Role::Server => in_block_data(Direction::Upload),
        };
        if segment && !BlockSegment::is_abort(data) {
            match BlockSegment::parse(data) {
                Ok(seg) => {
                    step.frame = Some(SdoFrame::BlockSegment(seg));
                    if let Some(o) = &mut self.open {
                        step.target = Some((o.index, o.subindex));
                        o.block.push(seg.data);
                        o.last_seen = seg.last;
                    }
                }
                Err(e) => step.error = Some(e.to_string()),
            }
            return step;
        }
        match role {
            Role::Client => match Request::parse(data) {
                Ok(r) => {
                    step.frame = Some(SdoFrame::Request(r));
                    self.request(r, &mut step);
                }
                Err(e) => step.error = Some(e.to_string()),
            },
            Role::Server => match Response::parse(data) {
                Ok(r) => {
                    step.frame = Some(SdoFrame::Response(r));
                    self.response(r, &mut step);
                }
                Err(e) => step.error = Some(e.to_string()),
            },
        }
        if step.target.is_none() {
            step.target = self.open.as_ref().map(|o| (o.index, o.subindex));
        }
        step
    }

    fn start(&mut self, index: u16, subindex: u8, direction: Direction, method: &'static str) {
        self.open = Some(Open {
            index,
            subindex,
            direction,
            method,
            phase: Phase::Initiated,
            data: Vec::new(),
            block: Vec::new(),
            last_seen: false,
            unused: 0,
        });
    }

    fn finish(&mut self, abort: Option<AbortCode>, step: &mut Step) {
        if let Some(o) = self.open.take() {
            step.target = Some((o.index, o.subindex));
            step.ended = Some(Transfer {
                index: o.index,
                subindex: o.subindex,
                direction: o.direction,
                data: o.data,
                abort,
                method: o.method,
            });
        }
    }

    fn open_in(&mut self, direction: Direction, phase: Phase) -> Option<&mut Open> {
        self.open
            .as_mut()
            .filter(|o| o.direction == direction && o.phase == phase)
    }

    fn request(&mut self, r: Request, step: &mut Step) {
        match r {
            Request::DownloadInitiate { index, sub, data } => {
                step.target = Some((index, sub));
                match data {
                    Initiate::Expedited { data, len } => {
                        self.start(index, sub, Direction::Download, "expedited");
                        if let Some(o) = &mut self.open {
                            o.data = data[..usize::from(len.unwrap_or(4))].to_vec();
                        }
                    }
                    Initiate::Segmented { .. } => {
                        self.start(index, sub, Direction::Download, "segmented")
                    }
                }
            }
            Request::DownloadSegment {
                data, len, last, ..
            } => match self.open_in(Direction::Download, Phase::Data) {
                Some(o) => {
                    o.data.extend_from_slice(&data[..usize::from(len)]);
                    o.last_seen = last;
                }
                None => step.note = Some("a segment of a transfer whose start is not in the trace"),
            },
            Request::UploadInitiate { index, sub } => {
                step.target = Some((index, sub));
                self.start(index, sub, Direction::Upload, "expedited");
            }
            Request::UploadSegment { .. } => {
                if self.open_in(Direction::Upload, Phase::Data).is_none() {
                    step.note = Some("a segment of a transfer whose start is not in the trace");
                }
            }
            Request::BlockDownloadInitiate { index, sub, .. } => {
                step.target = Some((index, sub));
                self.start(index, sub, Direction::Download, "block");
            }
            Request::BlockDownloadEnd { unused, .. } => match self
                .open_in(Direction::Download, Phase::End)
            {
                Some(o) => o.unused = unused,
                None => step.note = Some("the end of a transfer whose start is not in the trace"),
            },
            Request::BlockUploadInitiate { index, sub, .. } => {
                step.target = Some((index, sub));
                self.start(index, sub, Direction::Upload, "block");
            }
            Request::BlockUploadStart => {
                if let Some(o) = self.open_in(Direction::Upload, Phase::Initiated) {
                    o.phase = Phase::Data;
                }
            }
            Request::BlockUploadAck { ack_seq, .. } => {
                if let Some(o) = self
                    .open
                    .as_mut()
                    .filter(|o| o.method == "block" && o.direction == Direction::Upload)
                {
                    commit_block(o, ack_seq);
                }
            }
            Request::BlockUploadEnd => {
                if self.open_in(Direction::Upload, Phase::End).is_some() {
                    self.finish(None, step);
                }
            }
            Request::Abort { index, sub, code } => {
                step.target = Some((index, sub));
                self.finish(Some(code), step);
            }
        }
    }

    fn response(&mut self, r: Response, step: &mut Step) {
        match r {
            Response::DownloadInitiate { index, sub } => {
                step.target = Some((index, sub));
                let Some(o) = self.open_in(Direction::Download, Phase::Initiated) else {
                    return;
                };
                if o.method == "expedited" {
                    self.finish(None, step);
                } else {
                    o.phase = Phase::Data;
                }
            }
            Response::DownloadSegment { .. } => {
                // The confirmation of a segment: the last one's ends the transfer.
                if self
                    .open_in(Direction::Download, Phase::Data)
                    .is_some_and(|o| o.last_seen)
                {
                    self.finish(None, step);
                }
            }
            Response::UploadInitiate { index, sub, data } => {
                step.target = Some((index, sub));
                let Some(o) = self.open_in(Direction::Upload, Phase::Initiated) else {
                    return;
                };
                match data {
                    Initiate::Expedited { data, len } => {
                        o.data = data[..usize::from(len.unwrap_or(4))].to_vec();
                        o.method = "expedited";
                        self.finish(None, step);
                    }
                    Initiate::Segmented { .. } => {
                        o.method = "segmented";
                        o.phase = Phase::Data;
                    }
                }
            }
            Response::UploadSegment {
                data, len, last, ..
            } => match self.open_in(Direction::Upload, Phase::Data) {
                Some(o) => {
                    o.data.extend_from_slice(&data[..usize::from(len)]);
                    if last {
                        self.finish(None, step);
                    }
                }
                None => step.note = Some("a segment of a transfer whose start is not in the trace"),
            },
            Response::BlockDownloadInitiate { index, sub, .. } => {
                step.target = Some((index, sub));
                if let Some(o) = self.open_in(Direction::Download, Phase::Initiated) {
                    o.phase = Phase::Data;
                }
            }
            Response::BlockDownloadAck { ack_seq, .. } => {
                if let Some(o) = self.open_in(Direction::Download, Phase::Data) {
                    commit_block(o, ack_seq);
                }
            }
            Response::BlockDownloadEnd => {
                if let Some(o) = self.open_in(Direction::Download, Phase::End) {
                    let keep = o.data.len().saturating_sub(usize::from(o.unused));
                    o.data.truncate(keep);
                    self.finish(None, step);
                }
            }
            Response::BlockUploadInitiate { index, sub, .. } => {
                step.target = Some((index, sub));
            }
            Response::BlockUploadEnd { unused, .. } => {
                if let Some(o) = self.open_in(Direction::Upload, Phase::End) {
                    let keep = o.data.len().saturating_sub(usize::from(unused));
                    o.data.truncate(keep);
                }
            }
            Response::Abort { index, sub, code } => {
                step.target = Some((index, sub));
                self.finish(Some(code), step);
            }
        }
    }
}

/// The receiver acknowledged the segments of the current block up to
/// `ack_seq`: they become data; the others will be sent again. After the
/// last segment was acknowledged the end frame follows.
fn commit_block(o: &mut Open, ack_seq: u8) {
    let acked = usize::from(ack_seq).min(o.block.len());
    for seg in &o.block[..acked] {
        o.data.extend_from_slice(seg);
    }
    if o.last_seen && acked == o.block.len() {
        o.phase = Phase::End;
    }
    o.block.clear();
    o.last_seen = false;
}
