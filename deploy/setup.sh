#!/usr/bin/env bash
# Installs every Debian 12 package robin-contact needs to build, test and run.
# Idempotent: when everything is present it returns without touching apt.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  # deploy/build.sh builds with Ninja and links with lld (faster than make and GNU ld on the
  # ~60 test executables).
  ninja-build lld
  clang libclang-rt-14-dev
  libeigen3-dev libsuitesparse-dev libblas-dev libopenblas0-pthread
  libzmq3-dev libsodium-dev cppzmq-dev libprotobuf-dev protobuf-compiler
  libspdlog-dev libfmt-dev
  libgmsh-dev gmsh
  libcli11-dev libtomlplusplus-dev libmuparser-dev nlohmann-json3-dev
  googletest libgtest-dev libgmock-dev libbenchmark-dev
  python3 python3-numpy python3-scipy python3-matplotlib python3-zmq python3-protobuf
  iproute2 procps shellcheck python3-yaml
  libdeflate-dev zlib1g-dev
  # ParaView 5.11 and its Python (paraview.simple, and the vtkmodules of its VTK 9.2, which the
  # tests read .vtu files with: python3-paraview conflicts with python3-vtk9 and replaces it on a
  # machine set up before), and a virtual X display for robin-paraview --screenshot
  # (tests/integration/robin_paraview_test.sh). 152 MB to download (python3-vtk9 was 49 MB).
  paraview python3-paraview xvfb xauth
  # tests/network/slurm_namespaces_test.sh runs deploy/slurm/robin-contact.sbatch on a SLURM
  # cluster it starts itself (its own munged, slurmctld and slurmds, configuration and key in
  # its work directory). On a host run by systemd, Debian enables munge.service (its own key
  # and socket under /etc/munge, /run/munge), and slurmctld/slurmd.service, which do not start
  # without /etc/slurm/slurm.conf; the test uses none of them.
  slurmctld slurmd slurm-client munge
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo_prefix=""
if [ "$(id -u)" -ne 0 ]; then sudo_prefix="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo_prefix apt-get update -qq
$sudo_prefix apt-get install -y -qq --no-install-recommends "${missing[@]}"
