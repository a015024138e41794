#!/usr/bin/env python3
"""Headless kidnapped-robot demo client.

Kidnaps the simulated robot to random poses (fdml_simulator ~kidnap), calls the
localizer's ~relocalize after each, and prints the truth, the best candidate,
the error, the number of candidates and the solve time; then a one-line summary.
Exit status: 0 when at least --min-success kidnaps were localized within the
tolerance, 1 otherwise, 2 when the nodes did not come up.
"""
import argparse
import bisect
import math
import sys
import threading

import rospy
from nav_msgs.msg import Odometry

from fdml_localization.srv import Kidnap, KidnapRequest, Relocalize


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def wrap(a):
    return (a + math.pi) % (2.0 * math.pi) - math.pi


class TruthHistory:
    """Ground-truth poses by stamp, interpolated at any recent time."""

    def __init__(self, topic):
        self._lock = threading.Lock()
        self._stamps = []
        self._poses = []
        rospy.Subscriber(topic, Odometry, self._on_odom, queue_size=200)

    def _on_odom(self, msg):
        p = msg.pose.pose
        with self._lock:
            self._stamps.append(msg.header.stamp.to_sec())
            self._poses.append((p.position.x, p.position.y, yaw_of(p.orientation)))
            if len(self._stamps) > 5000:
                del self._stamps[:1000]
                del self._poses[:1000]

    def at(self, stamp):
        with self._lock:
            if not self._stamps:
                return None
            i = bisect.bisect_left(self._stamps, stamp)
            if i <= 0:
                return self._poses[0]
            if i >= len(self._stamps):
                return self._poses[-1]
            t0, t1 = self._stamps[i - 1], self._stamps[i]
            a, b = self._poses[i - 1], self._poses[i]
        w = 0.0 if t1 <= t0 else (stamp - t0) / (t1 - t0)
        return (a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), wrap(a[2] + w * wrap(b[2] - a[2])))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kidnaps", type=int, default=5)
    parser.add_argument("--min-success", type=int, default=0)
    parser.add_argument("--pos-tol", type=float, default=0.05, help="[m]")
    parser.add_argument("--ang-tol", type=float, default=2.0, help="[deg]")
    parser.add_argument("--timeout", type=float, default=60.0, help="per relocalization [s]")
    parser.add_argument("--stop-when-unambiguous", action="store_true",
                        help="stop after the first correct answer with a single best candidate")
    args = parser.parse_args(rospy.myargv()[1:])

    rospy.init_node("fdml_demo_client")
    truth = TruthHistory("ground_truth")
    try:
        rospy.wait_for_service("fdml_simulator/kidnap", timeout=60.0)
        rospy.wait_for_service("fdml_localizer/relocalize", timeout=60.0)
    except rospy.ROSException as err:
        print("demo: the simulator or the localizer did not come up: %s" % err)
        return 2
    kidnap = rospy.ServiceProxy("fdml_simulator/kidnap", Kidnap)
    relocalize = rospy.ServiceProxy("fdml_localizer/relocalize", Relocalize)

    print("%-3s %-28s %-28s %9s %8s %5s %8s" % ("#", "truth (x, y, yaw)", "best (x, y, yaw)", "err [cm]",
                                               "err [deg]", "cands", "solve [s]"))
    good = 0
    errors = []
    for n in range(1, args.kidnaps + 1):
        moved = kidnap(KidnapRequest(random=True))
        if not moved.success:
            print("%-3d kidnap failed: %s" % (n, moved.message))
            continue
        res = relocalize(timeout=args.timeout)
        result = res.result
        truth_pose = truth.at(result.header.stamp.to_sec())
        if not res.success or not result.candidates or truth_pose is None:
            print("%-3d %-28s relocalization failed: %s" % (n, "", res.message))
            continue
        best = result.candidates[0].pose
        bx, by, byaw = best.position.x, best.position.y, yaw_of(best.orientation)
        err_pos = math.hypot(bx - truth_pose[0], by - truth_pose[1])
        err_ang = abs(math.degrees(wrap(byaw - truth_pose[2])))
        ok = err_pos <= args.pos_tol and err_ang <= args.ang_tol
        good += int(ok)
        errors.append((err_pos, err_ang))
        print("%-3d (%7.3f, %7.3f, %+6.3f)   (%7.3f, %7.3f, %+6.3f)   %9.2f %8.2f %5d %8.3f %s" % (
            n, truth_pose[0], truth_pose[1], truth_pose[2], bx, by, byaw, 100.0 * err_pos, err_ang,
            len(result.candidates), result.solve_time, "ok" if ok else "MISS"))
        cands = result.candidates
        unambiguous = len(cands) == 1 or cands[0].inliers > cands[1].inliers
        if args.stop_when_unambiguous and ok and unambiguous:
            args.kidnaps = n
            break
    median_cm = sorted(e[0] for e in errors)[len(errors) // 2] * 100.0 if errors else float("nan")
    print("summary: %d of %d kidnaps relocalized within %.0f cm and %.0f deg; median error %.2f cm" % (
        good, args.kidnaps, args.pos_tol * 100.0, args.ang_tol, median_cm))
    return 0 if good >= args.min_success else 1


if __name__ == "__main__":
    sys.exit(main())
