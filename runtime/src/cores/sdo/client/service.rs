//! The client as a [`Service`]: frames in (only data frames on the
//! channel's response identifier, while a transfer runs), frames and events
//! out, the per-step timeout.

use super::ClientEvent;
use super::{Phase, SdoClient};
use crate::sdo::AbortCode;
use crate::sdo::SdoError;
use crate::sdo::proto::{BlockSegment, Request, Response};
use crate::{Frame, Instant, Service};

impl Service for SdoClient {
    type Event = ClientEvent;

    fn handle_frame(&mut self, now: Instant, frame: &Frame) {
        if self.is_idle() || frame.is_remote() || frame.id() != self.config.channel.response {
            return;
        }
        let data = frame.data();
        if let Phase::BlockUpload(block) = self.phase
            && !BlockSegment::is_abort(data)
        {
            self.on_block_upload_segment(now, block, data);
            return;
        }
        match Response::parse(data) {
            Ok(response) => self.on_response(now, response),
            Err(error) => {
                // Abort as for any invalid command, and report the frame.
                let code = error.abort_code();
                self.send(Request::Abort {
                    index: self.index,
                    sub: self.sub,
                    code,
                });
                let mut frame = [0u8; 8];
                let len = data.len().min(8);
                frame[..len].copy_from_slice(&data[..len]);
                self.finish_failed(SdoError::BadResponse {
                    frame,
                    len: len as u8,
                    error,
                });
            }
        }
    }

    fn handle_timeout(&mut self, now: Instant) {
        if let Some(deadline) = self.poll_timeout()
            && now >= deadline
        {
            self.send(Request::Abort {
                index: self.index,
                sub: self.sub,
                code: AbortCode::Timeout,
            });
            self.finish_failed(SdoError::Timeout);
        }
    }

    fn poll_transmit(&mut self) -> Option<Frame> {
        let data = match self.tx.pop() {
            Some(data) => data,
            None => self.next_block_segment()?,
        };
        Some(Frame::with_id(self.config.channel.request, data, 8))
    }

    fn poll_event(&mut self) -> Option<ClientEvent> {
        self.events.pop_front()
    }

    /// The server's next frame is due then; `None` while idle, while a
    /// streamed download waits for the caller's data, and while segments of
    /// a block download are still to be sent (the wait for the block ack
    /// counts from the frame that started the sub-block).
    fn poll_timeout(&self) -> Option<Instant> {
        match self.phase {
            Phase::Idle | Phase::DownloadData { .. } => None,
            Phase::BlockDownload(block) if block.has_unsent() => None,
            _ => Some(self.deadline),
        }
    }
}
