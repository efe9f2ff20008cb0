#!/usr/bin/env bash
# Installs, from Debian, whichever build and test dependencies of slideid are missing.
# Idempotent: a machine that already has everything is left alone (no apt-get update).
set -euo pipefail

packages=(
  build-essential cmake
  ccache                 # compiler cache: CI's fresh clones recompile only what changed
  libeigen3-dev          # linear algebra
  libceres-dev           # robust least squares and covariance
  libboost-program-options-dev  # command lines and INI scene files
  libfccp-dev            # fast-cpp-csv-parser: push logs
  libssl-dev             # OpenSSL's SHA-256: a resumed batch knows a log by its content hash
  nlohmann-json3-dev     # JSON: the identify result, imported MIT push files (io/)
  libgtest-dev           # unit and recovery tests
  libbenchmark-dev       # step and estimator benchmarks
  libmujoco-dev          # MuJoCo 2.2: the prediction baseline (benchmarks/mujoco_baseline.cc)
  gnuplot-nox            # plot-log
  pybind11-dev python3-dev python3-numpy  # the Python module, for Debian's /usr/bin/python3
  python3-pytest         # the Python module's tests
  python3-distributed    # slideid.dask: many logs on a Dask cluster (docs/scale-out.md)
  librosbag-dev libgeometry-msgs-dev libtf2-msgs-dev  # import-log --format rosbag: ROS 1 bags (io/rosbag_push.h)
  libzstd-dev liblz4-dev zlib1g-dev  # import-log --format mcap: chunk compression and CRC-32 (io/mcap_file.h)
  libhdf5-dev            # import-log --format mit-push-h5: the MIT push dataset's .h5 files (io/mit_push_h5.h)
  clang-format           # the code's format (.clang-format), checked by scripts/check_format.sh
  clang libclang-rt-14-dev  # fuzz targets: libFuzzer and clang's sanitizer runtimes (scripts/fuzz.sh)
  chromium               # headless browser: renders the HTML report in a test (tests/report_browser_test.cc)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all dependencies present"
fi
