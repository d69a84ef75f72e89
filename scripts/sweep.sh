#!/usr/bin/env bash
# Rate sweep: encode each given animation with JPEG, MPEG-4 and the temporal DCT at several
# qualities (and MPEG-4 at fixed quantisers, when asked), and append one CSV row per encoding (bpvf counts every byte of the file; RMSE is the
# papers' surface measure, as a fraction of the bbox diagonal). Times are whole-process figures from
# GNU time: wall seconds, CPU seconds (user + system, steadier than wall on a shared machine) and
# peak resident memory.
#   scripts/sweep.sh OUT.csv INPUT...
# env: JPEG_QUALITIES, MPEG4_QUALITIES, QSCALES, TDCT_QUALITIES, HEVC_QUALITIES,
#      HEVC_INTRA_QUALITIES, HEVC_DEPTHS, AV1_QUALITIES, AV1_INTRA_QUALITIES, AV1_DEPTHS,
#      LATTICES, VARIANTS, EXTRA, MCGV_BIN
#   VARIANTS   space-separated encoder variants, each a '+'-joined list of
#              skinning (--predictor skinning), affine (--predictor affine), decimation
#              (--segmentation decimation) and kmeans (--segmentation kmeans), or
#              `default` (no extra flag). Unset: the default encoder only. A variant's rows are
#              labelled in the codec column as CODEC+VARIANT (mpeg4+skinning, jpeg+skinning+decimation),
#              so plots and tables treat each as its own series; the CSV columns stay the same.
#   JPEG_QUALITIES, MPEG4_QUALITIES  --quality values; unset: the defaults below (the five
#              qualities of the rate-control issue, and 97 for MPEG-4's top end); set but empty: none.
#   QSCALES    `--codec mpeg4 --qscale N` runs (the codec's own quantiser, overriding the one
#              --quality picks); unset or empty: none.
#   TDCT_QUALITIES  --quality values of `--codec tdct` runs, made only when the binary's
#              `encode --help` mentions tdct (default: the JPEG qualities); empty: none.
#   HEVC_QUALITIES, HEVC_INTRA_QUALITIES  --quality values of `--codec hevc` runs (P-frames; codec
#              column `hevc`) and of all-intra `--codec hevc --gop 1` runs (`hevc-intra`), made only
#              when the binary's `encode --help` mentions hevc; unset or empty: none.
#   HEVC_DEPTHS  --bit-depth values of the hevc runs (default: the binary's default only); a depth
#              other than the default is labelled hevc@12, hevc-intra@12.
#   EXTRA      flags added to every encode (e.g. `--predictor affine --segmentation kmeans`, which
#              codes one motion model instead of the automatic choice's candidates).
#   AV1_QUALITIES, AV1_INTRA_QUALITIES, AV1_DEPTHS  the same for `--codec av1` (codec columns av1,
#              av1-intra, av1@12, av1-intra@12), made only when `encode --help` mentions av1.
#   LATTICES   --lattice values of the jpeg, mpeg4, hevc and av1 runs (WxH or auto; default: auto only);
#              a fixed lattice is labelled with the size the stream really holds (`inspect --json`),
#              jpeg@128x128, hevc@12@128x128; tdct has no lattice and runs once. A failed encoding on
#              a fixed lattice (one the charts do not fit) is reported on stderr and skipped.
set -euo pipefail
bin=${MCGV_BIN:-target/release/mcgv-video}
out=$1; shift
qualities=${JPEG_QUALITIES-"10 30 50 75 90"}
mpeg4_qualities=${MPEG4_QUALITIES-"10 30 50 75 90 97"}
qscales=${QSCALES-}
hevc_qualities=${HEVC_QUALITIES-}
hevc_intra_qualities=${HEVC_INTRA_QUALITIES-}
hevc_depths=${HEVC_DEPTHS:-default}
lattices=${LATTICES:-auto}
if [ -n "$hevc_qualities$hevc_intra_qualities" ] && ! "$bin" encode --help | grep -qw hevc; then
    echo "sweep.sh: $bin has no hevc codec; HEVC_QUALITIES ignored" >&2
    hevc_qualities=""; hevc_intra_qualities=""
fi
av1_qualities=${AV1_QUALITIES-}
av1_intra_qualities=${AV1_INTRA_QUALITIES-}
av1_depths=${AV1_DEPTHS:-default}
if [ -n "$av1_qualities$av1_intra_qualities" ] && ! "$bin" encode --help | grep -qw av1; then
    echo "sweep.sh: $bin has no av1 codec; AV1_QUALITIES ignored" >&2
    av1_qualities=""; av1_intra_qualities=""
fi
tdct_qualities=${TDCT_QUALITIES-$qualities}
variants=${VARIANTS:-default}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
# Encoder flags of a variant; fails on an unknown name, before anything is encoded.
variant_flags() {
    local part flags=() parts
    [ "$1" = default ] && return 0
    IFS=+ read -ra parts <<<"$1"
    for part in "${parts[@]}"; do
        case $part in
            skinning) flags+=(--predictor skinning) ;;
            affine) flags+=(--predictor affine) ;;
            decimation) flags+=(--segmentation decimation) ;;
            kmeans) flags+=(--segmentation kmeans) ;;
            *) echo "sweep.sh: unknown variant part '$part' in '$1' (skinning, affine, decimation, kmeans, default)" >&2
               return 1 ;;
        esac
    done
    echo "${flags[*]}"
}
for variant in $variants; do variant_flags "$variant" >/dev/null; done
tdct=no
if [ -n "$tdct_qualities" ] && "$bin" encode --help | grep -qw tdct; then
    tdct=yes
elif [ -n "${TDCT_QUALITIES:-}" ]; then
    echo "sweep.sh: $bin has no tdct codec; TDCT_QUALITIES ignored" >&2
fi
[ -s "$out" ] || echo "sequence,codec,setting,bytes,bpvf,rmse,vertex_rmse,kg_error,hausdorff,encode_s,decode_s,encode_cpu_s,decode_cpu_s,encode_rss_kb,decode_rss_kb,frames,vertices" > "$out"
field() { sed -E "s/.*\"$1\":([0-9.eE+-]+).*/\1/" <<<"$2"; }
# Runs a command under GNU time; prints "wall cpu max_rss_kb", nothing if the command fails.
measure() {
    /usr/bin/time -f "%e %U %S %M" -o "$tmp/time" "$@" || return 1
    awk '{ printf "%s %.2f %s\n", $1, $2 + $3, $4 }' "$tmp/time"
}
for input in "$@"; do
    name=$(basename "${input%/}"); name=${name%.*}
    runs=()
    for q in $qualities; do runs+=("jpeg --quality $q"); done
    for q in $mpeg4_qualities; do runs+=("mpeg4 --quality $q"); done
    for q in $qscales; do runs+=("mpeg4 --qscale $q"); done
    if [ "$tdct" = yes ]; then
        for q in $tdct_qualities; do runs+=("tdct --quality $q"); done
    fi
    for depth in $hevc_depths; do
        at=""; [ "$depth" = default ] || at="@$depth"
        for q in $hevc_qualities; do runs+=("hevc$at --quality $q"); done
        for q in $hevc_intra_qualities; do runs+=("hevc-intra$at --quality $q"); done
    done
    for depth in $av1_depths; do
        at=""; [ "$depth" = default ] || at="@$depth"
        for q in $av1_qualities; do runs+=("av1$at --quality $q"); done
        for q in $av1_intra_qualities; do runs+=("av1-intra$at --quality $q"); done
    done
    for variant in $variants; do
        read -ra extra <<<"$(variant_flags "$variant") ${EXTRA:-}"
        suffix=""; [ "$variant" = default ] || suffix="+$variant"
        for run in "${runs[@]}"; do
          read -r codec flag value <<<"$run"
          run_lattices=$lattices; [ "$codec" = tdct ] && run_lattices=auto
          for lattice in $run_lattices; do
            stream="$tmp/$name.mcgv"
            # hevc-intra@12 is `--codec hevc --gop 1 --bit-depth 12` (av1 alike).
            codec_flags=(--codec "${codec%%[-@]*}")
            case $codec in hevc-intra* | av1-intra*) codec_flags+=(--gop 1) ;; esac
            case $codec in *@*) codec_flags+=(--bit-depth "${codec#*@}") ;; esac
            [ "$lattice" = auto ] || codec_flags+=(--lattice "$lattice")
            if ! read -r ew ec em < <(measure "$bin" encode "$input" -o "$stream" --force "${codec_flags[@]}" "$flag" "$value" \
                ${extra[@]+"${extra[@]}"} --quiet) || [ -z "${em:-}" ]; then
                # Only a fixed lattice may be too small for the charts; any other failure stops the sweep.
                [ "$lattice" = auto ] && exit 1
                echo "sweep.sh: $name $codec $flag $value --lattice $lattice failed, skipped" >&2
                continue
            fi
            label=$codec
            if [ "$lattice" != auto ]; then
                used=$("$bin" inspect "$stream" --json | sed -E 's/.*"lattice":\[([0-9]+),([0-9]+)\].*/\1x\2/')
                label="$codec@$used"
            fi
            read -r dw dc dm < <(measure "$bin" decode "$stream" -o "$tmp/dec.pc2" --force --quiet)
            m=$("$bin" eval "$input" "$stream" --json --quiet --every-frame)
            printf '%s,%s,%s,%d,%.4f,%.6e,%.6e,%.5f,%.6e,%s,%s,%s,%s,%s,%s,%d,%d\n' \
                "$name" "$label$suffix" "${flag#--} $value" "$(stat -c %s "$stream")" "$(field bpvf "$m")" \
                "$(field rmse "$m")" "$(field vertex_rmse "$m")" "$(field kg_error "$m")" \
                "$(field hausdorff "$m")" "$ew" "$dw" "$ec" "$dc" "$em" "$dm" \
                "$(field frames "$m")" "$(field vertices "$m")" | tee -a "$out"
          done
        done
    done
done
