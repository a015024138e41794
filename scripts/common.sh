# Shared settings for the build, test and demo scripts (sourced, not run).
# The catkin workspace lives in a git-ignored folder (ws/) whose src/fdml_localization links
# to this checkout's files, so the checkout itself stays the package's source tree.
REPO_DIR="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
WS="${WS:-$REPO_DIR/ws}"
JOBS="${JOBS:-$(nproc)}"
# ROS tools run under the first python3 on PATH; Debian's has the ROS modules (rospkg, ...).
export PATH="/usr/bin:$PATH"
export ROS_HOME="${ROS_HOME:-$WS/ros_home}"
export ROS_LOG_DIR="${ROS_LOG_DIR:-$ROS_HOME/log}"

make_workspace() {
  # The package folder holds a link to each top-level entry of this checkout, except the
  # workspace itself: a link to the whole checkout would contain ws/ again, and roslaunch's
  # file search (which follows links) would loop through ws/src/fdml_localization/ws/...
  local pkg="$WS/src/fdml_localization"
  [ -L "$pkg" ] && rm "$pkg"
  mkdir -p "$pkg"
  local ws_real entry
  ws_real="$(cd "$WS" && pwd -P)"
  for entry in "$REPO_DIR"/*; do
    [ "$(cd "$entry" 2>/dev/null && pwd -P)" = "$ws_real" ] && continue
    ln -sfn "$entry" "$pkg/$(basename "$entry")"
  done
  find "$pkg" -maxdepth 1 -xtype l -delete  # entries removed from the checkout
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
