//! The mcgv-video decoder as WebAssembly: a thin C-ABI layer over the library's public API
//! ([`mcgv_video::Decoder`]), wrapped by `web/mcgv.js` (docs/web.md says why plain exports rather
//! than wasm-bindgen).
//!
//! JavaScript sees numbers only. A stream is a handle; its bytes grow by [`mcgv_stream_append`]
//! (the caller writes into the memory returned), [`mcgv_open`] opens what has arrived, and every
//! decode writes into a buffer the stream owns, whose address it returns (0 on failure). The
//! caller copies what it needs before the next call, which may move the buffer or grow the
//! memory. On failure [`mcgv_error_ptr`] and [`mcgv_error_len`] give the message; a panic (a bug:
//! the library returns errors on bad input) stores its message there before the trap, and the
//! instance is then dropped by the glue.

use mcgv_video::codec::Plane;
use mcgv_video::mesh::Triangle;
use mcgv_video::{Attributes, DecodeOptions, Decoder, Error, FirstFrame};
use std::cell::RefCell;
use std::io::Cursor;
use std::sync::Mutex;

/// Positions (vertices × frames) a stream may promise unless the caller says otherwise: 360 MB of
/// decoded frames, well inside WebAssembly's 4 GB.
const DEFAULT_MAX_POSITIONS: u64 = 30_000_000;

/// One stream: its bytes so far, its decoder once opened, and the buffers handed to JavaScript.
#[derive(Default)]
struct Stream {
    bytes: Vec<u8>,
    decoder: Option<Decoder<Cursor<Vec<u8>>>>,
    /// The first frame, read before the stream opens ([`mcgv_first_frame`]).
    first: Option<FirstFrame>,
    floats: Vec<f32>,
    words: Vec<u32>,
    text: Vec<u8>,
    picture: Vec<u16>,
}

thread_local! {
    /// The open streams by handle (a decoder is not `Send`: WebAssembly runs one thread here).
    static STREAMS: RefCell<Vec<Option<Stream>>> = const { RefCell::new(Vec::new()) };
}
static ERROR: Mutex<String> = Mutex::new(String::new());

fn set_error(message: String) {
    if let Ok(mut e) = ERROR.try_lock() {
        *e = message;
    }
}

/// Runs `f` on stream `handle`; an unknown handle or a failure stores the error and gives `None`.
fn with<T>(handle: u32, f: impl FnOnce(&mut Stream) -> Result<T, Error>) -> Option<T> {
    let result = STREAMS.with(|streams| {
        let Ok(mut streams) = streams.try_borrow_mut() else {
            return Err(Error::Usage(
                "the decoder is busy (called again from inside a call, or after a panic)".into(),
            ));
        };
        match streams.get_mut(handle as usize).and_then(Option::as_mut) {
            Some(stream) => f(stream),
            None => Err(Error::Usage(format!("no stream {handle}"))),
        }
    });
    result.map_err(|e| set_error(e.to_string())).ok()
}

fn opened(stream: &mut Stream) -> Result<&mut Decoder<Cursor<Vec<u8>>>, Error> {
    stream
        .decoder
        .as_mut()
        .ok_or_else(|| Error::Usage("the stream is not open".into()))
}

/// The triangles and attributes of the open stream, else of its first frame.
fn mesh(stream: &Stream) -> Result<(&[Triangle], Option<&Attributes>), Error> {
    match (&stream.decoder, &stream.first) {
        (Some(d), _) => Ok((d.triangles(), Some(d.attributes()))),
        (None, Some(f)) => Ok((&f.triangles, f.attributes.as_ref())),
        (None, None) => Err(Error::Usage("the stream is not open".into())),
    }
}

/// Installs the panic hook that keeps a panic's message for [`mcgv_error_ptr`]. Call once.
#[no_mangle]
pub extern "C" fn mcgv_init() {
    std::panic::set_hook(Box::new(|info| {
        set_error(format!("decoder panicked: {info}"))
    }));
}

/// The last error's message (UTF-8): its address.
#[no_mangle]
pub extern "C" fn mcgv_error_ptr() -> *const u8 {
    ERROR.try_lock().map_or(std::ptr::null(), |e| e.as_ptr())
}

/// The last error's message: its length in bytes.
#[no_mangle]
pub extern "C" fn mcgv_error_len() -> usize {
    ERROR.try_lock().map_or(0, |e| e.len())
}

/// A new, empty stream: its handle.
#[no_mangle]
pub extern "C" fn mcgv_stream_new() -> u32 {
    STREAMS.with(|streams| {
        let mut streams = streams.borrow_mut();
        match streams.iter().position(Option::is_none) {
            Some(free) => {
                streams[free] = Some(Stream::default());
                free as u32
            }
            None => {
                streams.push(Some(Stream::default()));
                (streams.len() - 1) as u32
            }
        }
    })
}

/// Frees a stream and everything it holds.
#[no_mangle]
pub extern "C" fn mcgv_stream_free(handle: u32) {
    STREAMS.with(|streams| {
        if let Some(slot) = streams.borrow_mut().get_mut(handle as usize) {
            *slot = None;
        }
    });
}

/// Makes room for `len` more bytes of the stream: the address the caller writes them to (0 when
/// the memory cannot grow).
#[no_mangle]
pub extern "C" fn mcgv_stream_append(handle: u32, len: usize) -> *mut u8 {
    with(handle, |s| {
        let start = s.bytes.len();
        s.bytes
            .try_reserve(len)
            .map_err(|e| Error::Usage(format!("{len} more bytes: {e}")))?;
        s.bytes.resize(start + len, 0);
        Ok(s.bytes[start..].as_mut_ptr())
    })
    .unwrap_or(std::ptr::null_mut())
}

/// Bytes of the stream so far.
#[no_mangle]
pub extern "C" fn mcgv_stream_len(handle: u32) -> usize {
    with(handle, |s| Ok(s.bytes.len())).unwrap_or(0)
}

/// Opens (again) the bytes so far: 1 on success, 0 on failure (see [`mcgv_error_ptr`]).
/// `max_bands` < 0: every band; `partial` ≠ 0: the bytes are the start of a stream still
/// arriving; `max_positions` 0: the default limit on vertices × frames.
#[no_mangle]
pub extern "C" fn mcgv_open(handle: u32, max_bands: i32, partial: u32, max_positions: f64) -> u32 {
    let options = DecodeOptions {
        max_bands: usize::try_from(max_bands).ok(),
        max_positions: match max_positions {
            p if p >= 1.0 => p as u64,
            _ => DEFAULT_MAX_POSITIONS,
        },
        partial: partial != 0,
    };
    with(handle, |s| {
        s.decoder = None;
        let decoder = Decoder::from_reader(Cursor::new(s.bytes.clone()), &options)?;
        s.decoder = Some(decoder);
        Ok(1)
    })
    .unwrap_or(0)
}

/// Reads the first frame of the bytes so far (the stream's first parts suffice): the address of
/// its info as JSON (vertices, frames, triangles, fps, codec, uvSets, materials, hasMaterials,
/// attributesKnown), [`mcgv_text_len`] its length; then [`mcgv_triangles`], [`mcgv_texcoords`],
/// [`mcgv_materials`] give its mesh until the stream opens, and [`mcgv_first_positions`] its
/// positions. 0 on failure (not enough bytes yet, or a bad stream).
#[no_mangle]
pub extern "C" fn mcgv_first_frame(handle: u32) -> *const u8 {
    with(handle, |s| {
        let first = Decoder::first_frame(Cursor::new(&s.bytes[..]), &DecodeOptions::default())?;
        let h = &first.header;
        let a = first.attributes.clone().unwrap_or_default();
        let names: Vec<String> = a.material_names.iter().map(|n| json_string(n)).collect();
        let json = format!(
            "{{\"vertices\":{},\"frames\":{},\"triangles\":{},\"fps\":{},\"codec\":{},\
             \"uvSets\":{},\"materials\":[{}],\"hasMaterials\":{},\"attributesKnown\":{}}}",
            h.vertices,
            h.frames,
            h.triangles,
            if h.frame_rate.is_finite() {
                h.frame_rate
            } else {
                0.0
            },
            json_string(codec_name(h.codec)),
            a.texcoords.len(),
            names.join(","),
            !a.materials.is_empty(),
            first.attributes.is_some()
        );
        s.first = Some(first);
        s.text = json.into_bytes();
        Ok(s.text.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

fn codec_name(id: u8) -> &'static str {
    mcgv_video::Codec::from_id(id).map_or("unknown", |c| c.name())
}

/// The positions of the first frame [`mcgv_first_frame`] read: `3 × vertices` floats.
#[no_mangle]
pub extern "C" fn mcgv_first_positions(handle: u32) -> *const f32 {
    with(handle, |s| {
        let first = s
            .first
            .as_ref()
            .ok_or_else(|| Error::Usage("no first frame read".into()))?;
        s.floats = first.positions.iter().flatten().copied().collect();
        Ok(s.floats.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// What the open stream holds, as JSON (see `web/mcgv.js`): its address; [`mcgv_text_len`] its
/// length. 0 on failure.
#[no_mangle]
pub extern "C" fn mcgv_info(handle: u32) -> *const u8 {
    with(handle, |s| {
        let d = opened(s)?;
        let json = info_json(d);
        s.text = json.into_bytes();
        Ok(s.text.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// The length of the text [`mcgv_info`] last gave.
#[no_mangle]
pub extern "C" fn mcgv_text_len(handle: u32) -> usize {
    with(handle, |s| Ok(s.text.len())).unwrap_or(0)
}

fn info_json(d: &Decoder<Cursor<Vec<u8>>>) -> String {
    let h = d.header();
    let a = d.attributes();
    let names: Vec<String> = a.material_names.iter().map(|n| json_string(n)).collect();
    let description = d.describe();
    let bands = description.as_ref().and_then(|x| x.bands.as_ref());
    let pictures = description.as_ref().and_then(|x| x.pictures.as_ref());
    let settings: Vec<String> = description.as_ref().map_or(Vec::new(), |x| {
        x.settings
            .iter()
            .map(|(k, v)| format!("{}:{v}", json_string(k)))
            .collect()
    });
    let bands = bands.map_or("null".into(), |b| {
        let lengths: Vec<String> = b.lengths.iter().map(u64::to_string).collect();
        format!(
            "{{\"total\":{},\"decoded\":{},\"lengths\":[{}]}}",
            b.lengths.len(),
            b.decoded,
            lengths.join(",")
        )
    });
    let pictures = pictures.map_or("null".into(), |p| {
        format!(
            "{{\"lattice\":[{},{}],\"bitDepth\":{}}}",
            p.lattice.0, p.lattice.1, p.bit_depth
        )
    });
    let segments: Vec<String> = d
        .segments()
        .iter()
        .map(|r| format!("[{},{}]", r.start, r.end))
        .collect();
    format!(
        "{{\"vertices\":{},\"frames\":{},\"triangles\":{},\"fps\":{},\"codec\":{},\
         \"uvSets\":{},\"materials\":[{}],\"hasMaterials\":{},\"segments\":[{}],\
         \"openSegment\":{},\"truncated\":{},\"bands\":{bands},\"pictures\":{pictures},\
         \"settings\":{{{}}},\"fileLength\":{}}}",
        h.vertices,
        h.frames,
        h.triangles,
        if h.frame_rate.is_finite() {
            h.frame_rate
        } else {
            0.0
        },
        json_string(d.codec().name()),
        a.texcoords.len(),
        names.join(","),
        !a.materials.is_empty(),
        segments.join(","),
        d.open_segment().map_or(-1, |s| s as i64),
        d.truncated(),
        settings.join(","),
        d.file_len()
    )
}

fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// The triangles (3 vertex indices each): the address of `3 × triangles` 32-bit words.
#[no_mangle]
pub extern "C" fn mcgv_triangles(handle: u32) -> *const u32 {
    with(handle, |s| {
        let words: Vec<u32> = mesh(s)?.0.iter().flatten().copied().collect();
        s.words = words;
        Ok(s.words.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Texture coordinate set `set` (u, v per vertex): the address of `2 × vertices` floats; 0 when
/// the stream has no such set.
#[no_mangle]
pub extern "C" fn mcgv_texcoords(handle: u32, set: u32) -> *const f32 {
    with(handle, |s| {
        let uv = mesh(s)?
            .1
            .ok_or_else(|| Error::Usage("the attributes have not arrived".into()))?
            .texcoords
            .get(set as usize)
            .ok_or_else(|| Error::Usage(format!("no texture coordinate set {set}")))?;
        let floats: Vec<f32> = uv.iter().flatten().copied().collect();
        s.floats = floats;
        Ok(s.floats.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Each triangle's material: the address of `triangles` words; 0 when the stream has none.
#[no_mangle]
pub extern "C" fn mcgv_materials(handle: u32) -> *const u32 {
    with(handle, |s| {
        let materials = mesh(s)?.1.map(|a| a.materials.clone()).unwrap_or_default();
        if materials.is_empty() {
            return Err(Error::Usage("the stream has no materials".into()));
        }
        s.words = materials;
        Ok(s.words.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Decodes frame `f`: the address of `3 × vertices` floats (x, y, z per vertex); 0 on failure.
#[no_mangle]
pub extern "C" fn mcgv_decode_frame(handle: u32, f: u32) -> *const f32 {
    with(handle, |s| {
        let frame = opened(s)?.decode_frame(f as usize)?;
        s.floats = frame.into_iter().flatten().collect();
        Ok(s.floats.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Decodes every frame in order: the address of `3 × vertices × frames` floats; 0 on failure.
#[no_mangle]
pub extern "C" fn mcgv_decode_all(handle: u32) -> *const f32 {
    with(handle, |s| {
        let d = opened(s)?;
        let h = d.header();
        let len = 3 * h.vertices as usize * h.frames as usize;
        let mut out = Vec::new();
        out.try_reserve_exact(len)
            .map_err(|e| Error::Usage(format!("{len} floats: {e}")))?;
        d.for_each_frame(&mcgv_video::Silent, |_, frame| {
            out.extend(frame.into_iter().flatten());
            Ok(())
        })?;
        s.floats = out;
        Ok(s.floats.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Frame `f`'s coded picture (a picture codec's): its address; [`mcgv_text_len`] its length.
/// Returns 0 on failure; `key` (the low bit of [`mcgv_coded_key`]) says whether decoding may
/// start there.
#[no_mangle]
pub extern "C" fn mcgv_coded_picture(handle: u32, f: u32) -> *const u8 {
    with(handle, |s| {
        let (bytes, key) = opened(s)?.coded_picture(f as usize)?;
        s.text = bytes;
        s.words = vec![u32::from(key)];
        Ok(s.text.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}

/// Whether the picture [`mcgv_coded_picture`] last gave is a key frame (1) or not (0).
#[no_mangle]
pub extern "C" fn mcgv_coded_key(handle: u32) -> u32 {
    with(handle, |s| Ok(s.words.first().copied().unwrap_or(0))).unwrap_or(0)
}

/// Room for a `width × height` picture of 16-bit samples decoded outside (x | y | z side by
/// side): the address the caller writes it to.
#[no_mangle]
pub extern "C" fn mcgv_picture_buffer(handle: u32, width: u32, height: u32) -> *mut u16 {
    with(handle, |s| {
        let len = width as usize * height as usize;
        s.picture.clear();
        s.picture
            .try_reserve_exact(len)
            .map_err(|e| Error::Usage(format!("{width}×{height} picture: {e}")))?;
        s.picture.resize(len, 0);
        Ok(s.picture.as_mut_ptr())
    })
    .unwrap_or(std::ptr::null_mut())
}

/// Decodes frame `f` from the `width × height` picture written to [`mcgv_picture_buffer`]: the
/// address of `3 × vertices` floats; 0 on failure.
#[no_mangle]
pub extern "C" fn mcgv_decode_frame_from_picture(
    handle: u32,
    f: u32,
    width: u32,
    height: u32,
) -> *const f32 {
    with(handle, |s| {
        let picture = Plane::new(width, height, std::mem::take(&mut s.picture))?;
        let decoder = opened(s)?;
        let frame = decoder.decode_frame_from_picture(f as usize, &picture);
        s.picture = picture.data;
        s.floats = frame?.into_iter().flatten().collect();
        Ok(s.floats.as_ptr())
    })
    .unwrap_or(std::ptr::null())
}
