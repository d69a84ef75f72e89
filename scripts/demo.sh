#!/usr/bin/env bash
# make demo: what a new user sees first.
set -euo pipefail
bin=target/release/mcgv-video
sample=media/CesiumMan.glb
"$bin" info "$sample"
