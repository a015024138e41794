#!/usr/bin/env bash
# Builds the package in Release in the private catkin workspace.
set -euo pipefail
source "$(dirname "$0")/common.sh"
catkin_build "$@"
