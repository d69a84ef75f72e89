//! Where the messages of the codec libraries (FFmpeg's `[hevc @ 0x…] PPS id out of range` on a
//! damaged stream) go: nowhere unless the application asks for them. A library must not write to
//! the stderr of the program that uses it; the error the call returns already says what failed,
//! and these lines are detail for a user who asks (`mcgv-video -v`).

use std::sync::RwLock;

/// Receives one message of a codec library: the library's name for what logged it (`hevc`,
/// `libdav1d`; empty when unknown) and the message, without its trailing newline.
pub type CodecLogSink = fn(source: &str, message: &str);

static SINK: RwLock<Option<CodecLogSink>> = RwLock::new(None);

/// Sends the codec libraries' warnings and errors to `sink`, or drops them (`None`, the default).
/// Applies to the whole process; without the `ffmpeg` feature there are no such messages.
pub fn set_codec_log(sink: Option<CodecLogSink>) {
    // A poisoned lock only means a sink panicked; the slot itself is still a plain value.
    *SINK.write().unwrap_or_else(|e| e.into_inner()) = sink;
}

/// The sink set by [`set_codec_log`], if any.
#[cfg_attr(not(feature = "ffmpeg"), allow(dead_code))]
pub(crate) fn codec_log_sink() -> Option<CodecLogSink> {
    *SINK.read().unwrap_or_else(|e| e.into_inner())
}
