//! The binary buffer of a written glTF, its buffer views and accessors, and the two containers: a GLB
//! file, or a `.gltf` whose buffer is embedded as a base64 `data:` URI (one file, like the GLB).

use gltf::json::Value;

/// A JSON object from `(key, value)` pairs.
pub(super) fn object<const N: usize>(fields: [(&str, Value); N]) -> Value {
    fields.into_iter().collect()
}

/// glTF component types.
pub(super) const FLOAT: u32 = 5126;
pub(super) const UNSIGNED_INT: u32 = 5125;
/// Buffer view targets.
pub(super) const ARRAY_BUFFER: u32 = 34962;
pub(super) const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The buffer being filled, with its views and accessors in glTF JSON form.
#[derive(Default)]
pub(super) struct BufferBuilder {
    pub(super) bin: Vec<u8>,
    pub(super) views: Vec<Value>,
    pub(super) accessors: Vec<Value>,
}

impl BufferBuilder {
    /// Appends `bytes` (4-byte aligned) as a buffer view; returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        let mut view = object([
            ("buffer", 0.into()),
            ("byteOffset", self.bin.len().into()),
            ("byteLength", bytes.len().into()),
        ]);
        if let (Some(t), Value::Object(map)) = (target, &mut view) {
            map.insert("target".into(), t.into());
        }
        self.bin.extend_from_slice(bytes);
        self.views.push(view);
        self.views.len() - 1
    }

    /// Appends opaque bytes (an image) as a buffer view with no target; returns its index.
    pub(super) fn raw(&mut self, bytes: &[u8]) -> usize {
        self.view(bytes, None)
    }

    /// Adds float vectors of `N` components as an accessor (`with_bounds`: with min and max);
    /// returns the accessor's index.
    pub(super) fn floats<const N: usize>(
        &mut self,
        data: &[[f32; N]],
        target: Option<u32>,
        with_bounds: bool,
    ) -> usize {
        let bytes: Vec<u8> = data
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        let view = self.view(&bytes, target);
        let kind = match N {
            1 => "SCALAR",
            2 => "VEC2",
            3 => "VEC3",
            _ => "VEC4",
        };
        let mut accessor = object([
            ("bufferView", view.into()),
            ("componentType", FLOAT.into()),
            ("count", data.len().into()),
            ("type", kind.into()),
        ]);
        if with_bounds {
            let mut lo = [f32::INFINITY; N];
            let mut hi = [f32::NEG_INFINITY; N];
            for v in data {
                for k in 0..N {
                    lo[k] = lo[k].min(v[k]);
                    hi[k] = hi[k].max(v[k]);
                }
            }
            if let Value::Object(map) = &mut accessor {
                map.insert("min".into(), lo.to_vec().into());
                map.insert("max".into(), hi.to_vec().into());
            }
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Adds triangle indices as an unsigned-int accessor; returns its index.
    pub(super) fn indices(&mut self, indices: &[u32]) -> usize {
        let bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(object([
            ("bufferView", view.into()),
            ("componentType", UNSIGNED_INT.into()),
            ("count", indices.len().into()),
            ("type", "SCALAR".into()),
        ]));
        self.accessors.len() - 1
    }
}

/// A GLB file: header, JSON chunk (space-padded), BIN chunk (zero-padded).
pub(super) fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let pad = |n: usize| (4 - n % 4) % 4;
    let json_len = json.len() + pad(json.len());
    let bin_len = bin.len() + pad(bin.len());
    let total = 12 + 8 + json_len + if bin.is_empty() { 0 } else { 8 + bin_len };
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json_len as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json);
    out.resize(out.len() + pad(json.len()), b' ');
    if !bin.is_empty() {
        out.extend_from_slice(&(bin_len as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(bin);
        out.resize(out.len() + pad(bin.len()), 0);
    }
    out
}

/// Standard base64 with padding (RFC 4648), for the `data:` URI of a `.gltf`.
pub(super) fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk[0],
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[(n >> (18 - 6 * k)) as usize & 63] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        let cases = [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ];
        for (plain, coded) in cases {
            assert_eq!(base64(plain.as_bytes()), coded);
        }
    }

    #[test]
    fn glb_chunks_are_aligned() {
        let out = glb(b"{}", &[1, 2, 3]);
        assert_eq!(out.len(), 12 + 8 + 4 + 8 + 4);
        assert_eq!(&out[20..24], b"{}  ");
        assert_eq!(u32::from_le_bytes([out[8], out[9], out[10], out[11]]), 36);
    }
}
