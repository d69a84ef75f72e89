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

/// Initialises FFmpeg once per process and routes its log to the application's sink
/// ([`crate::set_codec_log`]): warnings and errors, never printed by the library itself.
pub(crate) fn init() -> Result<()> {
    static INIT: OnceLock<std::result::Result<(), String>> = OnceLock::new();
    INIT.get_or_init(|| {
        ffmpeg::init().map_err(|e| e.to_string())?;
        route_log();
        Ok(())
    })
    .clone()
    .map_err(|e| Error::Codec(format!("ffmpeg init: {e}")))
}

/// FFmpeg's log lines go to [`log_line`] (x86-64, where FFmpeg's `va_list` is the pointer the
/// callback's type names); elsewhere FFmpeg is silenced, its errors being the calls' errors.
#[cfg(target_arch = "x86_64")]
fn route_log() {
    // SAFETY: `log_line` has the callback's signature and stays valid for the whole process.
    unsafe { ffmpeg::ffi::av_log_set_callback(Some(log_line)) };
}

#[cfg(not(target_arch = "x86_64"))]
fn route_log() {
    ffmpeg::util::log::set_level(ffmpeg::util::log::Level::Quiet);
}

/// FFmpeg's log callback: formats a warning or an error with FFmpeg's own formatter and hands it
/// to the sink with the name of what logged it (`hevc`, `libdav1d`), dropping it when there is
/// none. Each call is taken as a line: FFmpeg's codecs end their messages with a newline.
#[cfg(target_arch = "x86_64")]
unsafe extern "C" fn log_line(
    avcl: *mut std::ffi::c_void,
    level: std::ffi::c_int,
    fmt: *const std::ffi::c_char,
    vl: *mut ffmpeg::ffi::__va_list_tag,
) {
    use std::ffi::{c_char, c_int, CStr};
    let Some(sink) = crate::codec_log::codec_log_sink() else {
        return;
    };
    if level > ffmpeg::ffi::AV_LOG_WARNING {
        return;
    }
    let mut line = [0 as c_char; 1024];
    // No "[name @ 0x…]" prefix: the name is passed apart, and the address says nothing.
    let mut prefix: c_int = 0;
    // SAFETY: FFmpeg passes its own context, format and arguments; `line` is as long as said,
    // and the formatter writes a NUL-terminated string into it.
    let written = unsafe {
        ffmpeg::ffi::av_log_format_line2(
            avcl,
            level,
            fmt,
            vl,
            line.as_mut_ptr(),
            line.len() as c_int,
            &mut prefix,
        )
    };
    if written < 0 {
        return;
    }
    // SAFETY: as above, `line` holds a NUL-terminated string.
    let message = unsafe { CStr::from_ptr(line.as_ptr()) }.to_string_lossy();
    // SAFETY: a logging context starts with a pointer to its AVClass (FFmpeg's rule for av_log),
    // whose item_name gives a NUL-terminated name.
    let source = unsafe { item_name(avcl) };
    sink(&source, message.trim_end());
}

/// The name FFmpeg's AVClass gives the logging context `avcl` (empty when it has none).
///
/// # Safety
/// `avcl` is null or a context FFmpeg passed to its log callback.
#[cfg(target_arch = "x86_64")]
unsafe fn item_name(avcl: *mut std::ffi::c_void) -> String {
    if avcl.is_null() {
        return String::new();
    }
    // SAFETY: see the function's contract.
    unsafe {
        let class = *(avcl as *const *const ffmpeg::ffi::AVClass);
        match class.as_ref().and_then(|c| c.item_name) {
            Some(name) => {
                let name = name(avcl);
                if name.is_null() {
                    String::new()
                } else {
                    std::ffi::CStr::from_ptr(name).to_string_lossy().into_owned()
                }
            }
            None => String::new(),
        }
    }
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

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;
    use std::sync::Mutex;

    static LINES: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

    fn keep(source: &str, message: &str) {
        LINES
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .push((source.into(), message.into()));
    }

    #[test]
    fn ffmpeg_log_reaches_the_sink_named_after_its_codec() {
        crate::set_codec_log(Some(keep));
        let mut decoder = open_decoder("hevc", codec::Id::HEVC).expect("hevc decoder");
        // An IDR slice whose header names picture parameter set 0, which no packet has sent.
        let slice = [0, 0, 0, 1, 0x26, 0x01, 0xff, 0xff, 0xff, 0xff, 0xff, 0xff];
        // FFmpeg may refuse the packet or only log and drop the slice: either way it logs.
        let _ = send_packet("hevc", &mut decoder, &slice);
        crate::set_codec_log(None);
        let lines = LINES.lock().unwrap_or_else(|e| e.into_inner());
        assert!(
            lines
                .iter()
                .any(|(source, message)| source == "hevc" && message.contains("PPS")),
            "{lines:?}"
        );
        assert!(lines.iter().all(|(_, m)| !m.ends_with('\n')), "{lines:?}");
    }
}
