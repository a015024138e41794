# Shared settings for the build, test and demo scripts (sourced, not run).
# The catkin workspace lives in a git-ignored folder with this repository linked as
# its src/fdml_localization, so the checkout itself stays the package's source tree.
REPO_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${WS:-$REPO_DIR/ws}"
JOBS="${JOBS:-$(nproc)}"
# ROS tools run under the first python3 on PATH; Debian's has the ROS modules (rospkg, ...).
export PATH="/usr/bin:$PATH"
export ROS_HOME="${ROS_HOME:-$WS/ros_home}"
export ROS_LOG_DIR="${ROS_LOG_DIR:-$ROS_HOME/log}"

make_workspace() {
  mkdir -p "$WS/src"
  if [ ! -e "$WS/src/fdml_localization" ]; then
    ln -s "$REPO_DIR" "$WS/src/fdml_localization"
  fi
}

catkin_build() {
  make_workspace
  (cd "$WS" && catkin_make -j"$JOBS" \
      -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 \
      -DCATKIN_ENABLE_TESTING=ON "$@")
}

source_workspace() {
  # shellcheck disable=SC1091
  set +u
  source "$WS/devel/setup.bash"
  set -u
}
