//! What the FFmpeg picture codecs ([`super::mpeg4`], [`super::hevc`]) do alike through
//! `ffmpeg-next`: initialising FFmpeg, checking the GOP, opening a one-thread decoder, sending
//! packets and draining the encoder's packets and the decoder's pictures. Each error names the
//! codec (`codec`: "mpeg4", "hevc").

use crate::{Error, Result};
use ffmpeg_next as ffmpeg;
use ffmpeg_next::util::error::EAGAIN;
use ffmpeg_next::{codec, decoder, encoder, frame};
use std::sync::OnceLock;

/// An FFmpeg error in `context`, named after the codec.
pub(crate) fn error(codec: &str, context: &str, e: ffmpeg::Error) -> Error {
    Error::Codec(format!("{codec} {context}: {e}"))
}

/// Initialises FFmpeg once per process and quiets its logging to errors only.
pub(crate) fn init() -> Result<()> {
    static INIT: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    INIT.get_or_init(|| {
        ffmpeg::init().map_err(|e| e.to_string())?;
        ffmpeg::util::log::set_level(ffmpeg::util::log::Level::Error);
        Ok(())
    })
    .clone()
    .map_err(|e| Error::Codec(format!("ffmpeg init: {e}")))
}

/// The group of pictures as FFmpeg takes it: 1..=i32::MAX.
pub(crate) fn checked_gop(codec: &str, gop: usize) -> Result<u32> {
    u32::try_from(gop)
        .ok()
        .filter(|g| (1..=i32::MAX as u32).contains(g))
        .ok_or_else(|| Error::Codec(format!("{codec} gop {gop} must be ≥ 1")))
}

/// One thread: frame threading would delay output by a frame per thread, and pins the output.
pub(crate) fn one_thread() -> codec::threading::Config {
    codec::threading::Config {
        count: 1,
        ..Default::default()
    }
}

/// Opens FFmpeg's decoder `id` on one thread.
pub(crate) fn open_decoder(codec: &str, id: codec::Id) -> Result<decoder::Video> {
    init()?;
    let found = decoder::find(id)
        .ok_or_else(|| Error::Codec(format!("{codec} decoder missing from libavcodec")))?;
    let mut context = codec::Context::new_with_codec(found);
    context.set_threading(one_thread());
    context
        .decoder()
        .video()
        .map_err(|e| error(codec, "open decoder", e))
}

/// Sends one packet to the decoder; an empty packet is an error (it would tell FFmpeg to drain).
pub(crate) fn send_packet(codec: &str, inner: &mut decoder::Video, packet: &[u8]) -> Result<()> {
    if packet.is_empty() {
        return Err(Error::Codec(format!("{codec} empty packet")));
    }
    inner
        .send_packet(&ffmpeg::Packet::copy(packet))
        .map_err(|e| {
            error(
                codec,
                &format!("decode packet of {} bytes", packet.len()),
                e,
            )
        })
}

/// The encoder's next packet, or `None` when it needs more input or has ended.
pub(crate) fn next_packet(
    codec: &str,
    inner: &mut encoder::Video,
) -> Result<Option<ffmpeg::Packet>> {
    let mut packet = ffmpeg::Packet::empty();
    let status = inner.receive_packet(&mut packet);
    received(codec, "receive packet", status, packet)
}

/// The decoder's next picture, or `None` when it needs more input or has ended.
pub(crate) fn next_picture(
    codec: &str,
    inner: &mut decoder::Video,
) -> Result<Option<frame::Video>> {
    let mut picture = frame::Video::empty();
    let status = inner.receive_frame(&mut picture);
    received(codec, "receive picture", status, picture)
}

/// `out` when FFmpeg's receive call filled it, `None` when it needs more input or has ended.
fn received<T>(
    codec: &str,
    context: &str,
    status: std::result::Result<(), ffmpeg::Error>,
    out: T,
) -> Result<Option<T>> {
    match status {
        Ok(()) => Ok(Some(out)),
        Err(ffmpeg::Error::Other { errno: EAGAIN }) | Err(ffmpeg::Error::Eof) => Ok(None),
        Err(e) => Err(error(codec, context, e)),
    }
}
