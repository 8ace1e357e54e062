#!/usr/bin/env bash
# Builds the seed corpora of the fuzz targets (docs/fuzzing.md) OUTSIDE the repository: the first
# lines (at most 20, at most 4096 bytes of whole lines) of the real files under the shared data
# folder, plus hand-written edge cases. Nothing from the shared data is committed.
#
#   fuzz/make_seeds.sh [DATA_DIR] [CORPUS_DIR]     (defaults: ../shared/data, /tmp/fuzz-corpus)
#
# Creates CORPUS_DIR/<target> for tum tumv euroc kitti vins csv auto column_map stamp. The csv
# target's first byte picks its column map (kCsvColumnMaps in fuzz/trajectory_fuzzer.cc: 0 tum-like,
# 1 t_ns..v, 2 roll/pitch/yaw, 3 position only, 4 everything, 5 position only with skips); the
# column_map target's first line is a --columns spec; the stamp target's first byte holds options.
set -euo pipefail

here="$(cd "$(dirname "$0")" && pwd)"
data="${1:-$here/../../shared/data}"
corpus="${2:-/tmp/fuzz-corpus}"
[[ -d "$data" ]] || { echo "no data folder at $data" >&2; exit 1; }

targets=(tum tumv euroc kitti vins csv auto column_map stamp)
for t in "${targets[@]}"; do mkdir -p "$corpus/$t"; done

# head_of FILE: the first <= 20 lines of FILE, cut to whole lines within 4096 bytes.
head_of() {
  head -n 20 "$1" | awk 'BEGIN { n = 0 } { n += length($0) + 1; if (n > 4096 && NR > 1) exit; print }' | head -c 4096
}

# seed TARGET NAME [PREFIX]: stdin, after PREFIX (printf format, e.g. '\x02' or 'spec\n'), into the corpus.
seed() {
  local target="$1" name="$2" prefix="${3:-}"
  { printf -- "$prefix"; cat; } > "$corpus/$target/$name"
}

name_of() { echo "$1" | sed 's|^\./||; s|[/ ]|_|g'; }

cd "$data"
# Real files: which target each belongs to (the formats of tests/traj/shared_data_test.cc).
while IFS= read -r f; do
  n="$(name_of "$f")"
  case "$f" in
    *KITTI_*_times.txt) head_of "$f" | seed stamp "$n" '\x00' ;;  # one stamp per line; the seed uses the first
    *KITTI_*) head_of "$f" | seed kitti "$n" ;;
    *blackbird_imo*) head_of "$f" | seed tumv "$n" ;;
    *cerberus_a1*/vio.csv|*vins_mono_outputs*|*vio_perf*/vins*/*.csv)
      head_of "$f" | seed vins "$n"
      head_of "$f" | seed csv "$n" '\x01' ;;
    *cerberus_a1*) head_of "$f" | seed csv "$n" '\x01'
                   head_of "$f" | seed column_map "$n" 't_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz\n' ;;
    *crazyflie*|*dido*) head_of "$f" | seed csv "$n" '\x04'
                        head_of "$f" | seed column_map "$n" 't,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n' ;;
    *icub*) head_of "$f" | seed csv "$n" '\x02'
            head_of "$f" | seed column_map "$n" 't,px,py,pz,roll,pitch,yaw\n' ;;
    *.csv) head_of "$f" | seed euroc "$n" ;;
    *) head_of "$f" | seed tum "$n"
       head_of "$f" | seed csv "$n" '\x00' ;;
  esac
  head_of "$f" | seed auto "$n"
done < <(find . -type f \( -name '*.txt' -o -name '*.csv' -o -name '*.tum' \) | sort)

# Stamps: the first field of the first data line of every seed, under every option byte.
for f in "$corpus"/tum/* "$corpus"/euroc/* "$corpus"/vins/*; do
  stamp="$(grep -v '^#' "$f" | head -n 1 | sed 's/[ ,].*//')"
  for opt in '\x00' '\x01' '\x04' '\x08' '\x0c' '\x0d'; do
    printf '%s' "$stamp" | seed stamp "$(basename "$f")_$(printf "$opt" | od -An -tx1 | tr -d ' ')" "$opt"
  done
done

# Hand-written edge cases.
e() { printf -- "$2" > "$corpus/$1/$3"; }
e tum 'a b c d e f g h\n1 0 0 0 0 0 0 1\r\n# comment\n\n 2\t0 0 0  0 0 0 1\n3 1e308 -0 +4 0 0 0 1' edge_header_crlf_tabs
e tum '1.5 0 0 0 0 0 0 0\n' edge_zero_quaternion
e tum '1e12 0 0 0 0 0 0 1\n-9223372036.854775808 1 2 3 1e200 0 0 1\n' edge_stamp_range
e tum '1 nan 0 0 0 0 0 1\n2 inf 0 0 0 0 0 1\n3 1e-400 0 0 0 0 0 1\n4 4.9e-324 0 0 0 0 0 1\n' edge_special_numbers
e tumv '0 0 0 0 0 0 0 1 0 0 0\n0.1 1 2 3 0.1 0.2 0.3 0.9 -1 -2 -3\n' edge_tumv
e euroc '#timestamp,x,y,z,qw,qx,qy,qz\n1,0,0,0,1,0,0,0\n2, 0 ,0,0,1,0,0,0,\n' edge_trailing_comma
e euroc '#time(ns),x,y,z,qw,qx,qy,qz,vx,vy,vz,a,b,c,d,e,f\n1,0,0,0,1,0,0,0,1,2,3,4,5,6,7,8,9\n' edge_bias
e euroc '#timestamp\n1.5,0,0,0,1,0,0,0\n' edge_fractional_ns
e kitti '1 0 0 0 0 1 0 0 0 0 1 0\n1 1e160 0 0 0 1 0 0 0 0 1 0\n' edge_shear
e kitti '-1 0 0 0 0 -1 0 0 0 0 1 0\n0 1 0 0 -1 0 0 0 0 0 1 0\n' edge_rotations
e vins '1403715524907143168,0,0,0,1,0,0,0\n1403715524907143169,0,0,0,1,0,0,0,0,0,0\n' edge_mixed_count
e csv '\x00t x y z qx qy qz qw\n1,2,3,4,0,0,0,1\n' edge_header_commas
e csv '\x02t,x,y,z,r,p,y\n0,0,0,0,3.14159,1.5707963267948966,-3.14159\n1,0,0,0,0,1e-160,1e-160\n' edge_euler
e csv '\x03 1.5 x 1 2 3 extra\n2 _ 1 2 3\n' edge_position_only
e csv '\x05 1 a b 1 2 3 c\n' edge_position_skips
e column_map 't,px,py,pz\n1,2,3,4\n' edge_minimal
e column_map '_,t_us,pz,py,px,_,wx,wy,wz,skip,-\n_,1,2,3,4,_,5,6,7\n' edge_shuffled
e column_map 't,px,py,pz,qx,qy,qz,qw,roll\n' edge_invalid
e column_map ',t,px,py,pz,\n' edge_empty_roles
e auto '#timestamp [ns],p_RS_R_x [m]\n1,0,0,0,1,0,0,0\n' edge_euroc
e auto '1403715524907143168,0,0,0,1,0,0,0\n' edge_vins
e auto 't x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n' edge_tum_header
e auto '1 0 0 0 0 1 0 0 0 0 1 0\n' edge_kitti
e stamp '\x001403715529.112143517' edge_seconds
e stamp '\x001.403715529112143517e+09' edge_exponent
e stamp '\x00-9223372036.854775808' edge_min
e stamp '\x009223372036.854775807' edge_max
e stamp '\x009223372036.8547758075' edge_max_half
e stamp '\x0d1403715524907143168' edge_ns
e stamp '\x0d1403715524907143168.5' edge_ns_fraction
e stamp '\x020.000000000000000000000000000000000000000000000001e48' edge_scale_zero
e stamp '\x02\x7f1e-127' edge_scale_127
e stamp '\x02\x801e128' edge_scale_minus_128
e stamp '\x00123456789012345678901234567890123456789012345678901234567890e-60' edge_long_digits
e stamp '\x00.5e-9' edge_half
e stamp '\x001e99999999999999999' edge_huge_exponent

for t in "${targets[@]}"; do echo "$t: $(ls "$corpus/$t" | wc -l) seeds"; done
