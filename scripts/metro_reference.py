#!/usr/bin/env python3
"""Metro (PyMeshLab's Hausdorff filter) distances between two meshes, as one JSON object.

Usage: metro_reference.py A.obj B.obj [SAMPLES]

Prints {"forward": {...}, "backward": {...}, "diag": d}: "forward" samples A and measures to B,
"backward" the reverse. Each direction is one-sided, as Metro computes it: "rms" and "mean" come
from SAMPLES Monte Carlo face samples (uniform by area, so the plain RMS of the samples is the
area-weighted RMS); "max" is the largest over the face samples and every vertex (what our sampling covers too);
"max_with_edges" adds SAMPLES points along the edges, where a cracked copy's largest distances sit.
Distances are absolute (the meshes' own units); "diag" is A's bounding-box diagonal.
"""
import json
import sys

import pymeshlab


def one_sided(ms, sampled, target, samples):
    # maxdist: count every distance up to a whole diagonal (the default drops those beyond 50 %).
    big = pymeshlab.PercentageValue(100)
    faces = ms.get_hausdorff_distance(
        sampledmesh=sampled, targetmesh=target, samplevert=False, sampleedge=False,
        samplefauxedge=False, sampleface=True, samplenum=samples, maxdist=big)
    # Every vertex (a count of at least V takes them all); then points along the edges, where the
    # largest distances of a cracked copy sit and face samples seldom land.
    vertices = ms.get_hausdorff_distance(
        sampledmesh=sampled, targetmesh=target, samplevert=True, sampleedge=False,
        samplefauxedge=False, sampleface=False,
        samplenum=ms.mesh(sampled).vertex_number(), maxdist=big)
    edges = ms.get_hausdorff_distance(
        sampledmesh=sampled, targetmesh=target, samplevert=False, sampleedge=True,
        samplefauxedge=False, sampleface=False, samplenum=samples, maxdist=big)
    return {
        "rms": faces["RMS"],
        "mean": faces["mean"],
        "max": max(faces["max"], vertices["max"]),
        "max_with_edges": max(faces["max"], vertices["max"], edges["max"]),
        "samples": faces["n_samples"],
    }


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    samples = int(sys.argv[3]) if len(sys.argv) == 4 else 1_000_000
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(sys.argv[1])
    ms.load_new_mesh(sys.argv[2])
    result = {
        "forward": one_sided(ms, 0, 1, samples),
        "backward": one_sided(ms, 1, 0, samples),
        "diag": ms.mesh(0).bounding_box().diagonal(),
    }
    print(json.dumps(result))


if __name__ == "__main__":
    main()
