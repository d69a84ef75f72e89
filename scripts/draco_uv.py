"""The bytes Draco spends on a glTF file's texture coordinates, to compare with mcgv-video's ATTR part
(`mcgv-video inspect STREAM`, row "attributes"): DracoPy at compression level 10 encodes every
primitive's positions and faces (14-bit positions) once without and once with TEXCOORD_0 (12-bit,
mcgv-video's default `--uv-bits`); the difference is the UVs' cost.
    .venv/bin/python scripts/draco_uv.py media/CesiumMan.glb media/Fox.glb
"""
import json, struct, sys, numpy as np, DracoPy
CT = {5126: ('f4', 4), 5123: ('u2', 2), 5125: ('u4', 4), 5121: ('u1', 1)}
NC = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4}
def load(path):
    b = open(path, 'rb').read()
    jl = struct.unpack_from('<I', b, 12)[0]
    js = json.loads(b[20:20 + jl]); bin_ = b[20 + jl + 8:]
    def acc(i):
        a = js['accessors'][i]; bv = js['bufferViews'][a['bufferView']]
        dt, sz = CT[a['componentType']]; n = NC[a['type']]
        off = bv.get('byteOffset', 0) + a.get('byteOffset', 0)
        stride = bv.get('byteStride', sz * n)
        raw = np.frombuffer(bin_, dtype=np.uint8, count=stride * (a['count'] - 1) + sz * n, offset=off)
        out = np.lib.stride_tricks.as_strided(raw, (a['count'], sz * n), (stride, 1)).copy()
        return out.view('<' + dt).reshape(a['count'], n)
    P, U, F = [], [], []; base = 0
    for m in js['meshes']:
        for p in m['primitives']:
            pos = acc(p['attributes']['POSITION']); uv = acc(p['attributes']['TEXCOORD_0'])
            idx = (acc(p['indices']) if 'indices' in p else np.arange(len(pos))).reshape(-1, 3).astype(np.int64)
            P.append(pos); U.append(uv); F.append(idx + base); base += len(pos)
    return np.vstack(P).astype(np.float32), np.vstack(U).astype(np.float32), np.vstack(F).astype(np.uint32)
for path in sys.argv[1:]:
    P, U, F = load(path)
    without = len(DracoPy.encode(P.astype(np.float64), F, quantization_bits=14, compression_level=10))
    with_ = len(DracoPy.encode(P.astype(np.float64), F, quantization_bits=14, compression_level=10, tex_coord=U.astype(np.float64), tex_coord_quantization_bits=12))
    print(f"{path}: {len(P)} vertices {len(F)} triangles; draco without UVs {without} with {with_}: UVs {with_ - without} bytes")
