#!/usr/bin/env bash
# Installs the Debian 12 packages fdml_localization needs to build, test and
# run its demo. Idempotent: when everything is present it only runs dpkg-query.
set -euo pipefail

PACKAGES=(
  # build tools and the catkin/ROS 1 toolchain (Debian's own ROS packages)
  build-essential cmake catkin ros-base-dev ros-message-generation
  ros-message-runtime python3-catkin-pkg python3-rostest python3-roslaunch
  librostest-dev
  # ROS libraries the nodes use
  libroscpp-dev libtf2-ros-dev libtf2-geometry-msgs-dev libtf2-dev
  libgeometry-msgs-dev libsensor-msgs-dev libnav-msgs-dev libstd-msgs-dev
  libstd-srvs-dev libvisualization-msgs-dev libdiagnostic-updater-dev
  libdiagnostic-msgs-dev
  # core library and tools
  libeigen3-dev libboost-dev libyaml-cpp-dev libstb-dev
  libgtest-dev googletest libbenchmark-dev
  # demo, visualisation and plots
  rviz xvfb imagemagick python3-matplotlib python3-yaml
  # python message modules for the demo client and rostopic
  python3-rospy python3-std-msgs python3-geometry-msgs python3-nav-msgs python3-sensor-msgs
  python3-std-srvs python3-visualization-msgs
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install_deps: installing ${#missing[@]} missing package(s): ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install_deps: not root and no sudo; install these by hand: ${missing[*]}" >&2
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
