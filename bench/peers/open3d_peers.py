#!/usr/bin/env python3
"""Open3D peers on a TUM RGB-D folder, frame to frame with the previous motion as the guess,
poses stamped with the depth time (as cvo_run_sequence does):
  open3d_colored_icp  multi-scale colored ICP (Park et al. 2017) on the full RGB-D clouds
  open3d_rgbd_hybrid  RGB-D odometry with the hybrid (photometric + geometric) term
Usage: open3d_peers.py TUM_DIR METHOD OUT_FILE [--stride N]   (Debian's python3-open3d, numpy)
  --stride N  every N-th frame, frame k against frame k-N (as cvo_run_sequence --stride; 1)
The time per frame (median, p95) runs from the decoded images to the pose, as cvo_run_sequence's
`total` does: reading the PNGs is outside it."""
import argparse
import statistics
import sys
import time

import numpy as np
import open3d as o3d

# fr1 pinhole (Open3D's odometry takes no distortion), TUM depth PNG scale.
FX, FY, CX, CY = 517.3, 516.5, 318.6, 255.3
DEPTH_SCALE = 5000.0


def read_associations(folder):
    rows = []
    with open(f"{folder}/associations.txt") as listing:
        for line in listing:
            fields = line.split()
            if fields and not fields[0].startswith("#"):
                rows.append((float(fields[2]), f"{folder}/{fields[1]}", f"{folder}/{fields[3]}"))
    return rows


def rgbd_image(colour, depth):
    return o3d.geometry.RGBDImage.create_from_color_and_depth(
        colour, depth, depth_scale=DEPTH_SCALE, depth_trunc=10.0, convert_rgb_to_intensity=False)


def colored_icp(previous, current, guess):
    """previous <- current by multi-scale colored ICP (voxel 4, 2, 1 cm), as Open3D's tutorial."""
    motion = guess
    for voxel, iterations in ((0.04, 50), (0.02, 30), (0.01, 14)):
        source = current.voxel_down_sample(voxel)
        target = previous.voxel_down_sample(voxel)
        for cloud in (source, target):
            cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=2 * voxel, max_nn=30))
        try:
            result = o3d.pipelines.registration.registration_colored_icp(
                source, target, 1.5 * voxel, motion,
                o3d.pipelines.registration.TransformationEstimationForColoredICP(),
                o3d.pipelines.registration.ICPConvergenceCriteria(
                    relative_fitness=1e-6, relative_rmse=1e-6, max_iteration=iterations))
        except RuntimeError as error:  # no correspondences at this scale: keep the coarser result
            print(f"colored ICP at {voxel} m: {str(error).splitlines()[0][-60:]}", file=sys.stderr)
            break
        motion = result.transformation
    return motion


def main():
    parser = argparse.ArgumentParser(description="Open3D peers on a TUM RGB-D folder")
    parser.add_argument("folder")
    parser.add_argument("method", choices=("open3d_colored_icp", "open3d_rgbd_hybrid"))
    parser.add_argument("out_path")
    parser.add_argument("--stride", type=int, default=1)
    args = parser.parse_args()
    if args.stride < 1:
        sys.exit("--stride must be >= 1")
    folder, method, out_path = args.folder, args.method, args.out_path
    intrinsic = o3d.camera.PinholeCameraIntrinsic(640, 480, FX, FY, CX, CY)
    frames = read_associations(folder)[::args.stride]
    pose = np.eye(4)
    motion = np.eye(4)
    previous = None
    times = []
    lines = []
    for stamp, rgb_path, depth_path in frames:
        # Decoding stays outside the timed part (the runner's `total` excludes it too).
        colour, depth = o3d.io.read_image(rgb_path), o3d.io.read_image(depth_path)
        start = time.perf_counter()
        image = rgbd_image(colour, depth)
        if method == "open3d_colored_icp":
            current = o3d.geometry.PointCloud.create_from_rgbd_image(image, intrinsic)
            if previous is not None:
                motion = colored_icp(previous, current, motion)
        elif method == "open3d_rgbd_hybrid":
            current = image
            if previous is not None:
                # compute_rgbd_odometry(source, target) returns target <- source.
                ok, result, _ = o3d.pipelines.odometry.compute_rgbd_odometry(
                    current, previous, intrinsic, motion,
                    o3d.pipelines.odometry.RGBDOdometryJacobianFromHybridTerm(),
                    o3d.pipelines.odometry.OdometryOption())
                if ok:
                    motion = result
                else:
                    print(f"{stamp}: odometry failed; keeping the guess", file=sys.stderr)
        if previous is not None:
            pose = pose @ motion
            times.append(1000 * (time.perf_counter() - start))
        previous = current
        q = rotation_to_quaternion(pose[:3, :3])
        t = pose[:3, 3]
        lines.append(f"{stamp:.6f} {t[0]:.9f} {t[1]:.9f} {t[2]:.9f} "
                     f"{q[0]:.9f} {q[1]:.9f} {q[2]:.9f} {q[3]:.9f}")
    with open(out_path, "w") as out:
        out.write("# timestamp tx ty tz qx qy qz qw\n" + "\n".join(lines) + "\n")
    times.sort()
    p95 = times[int(0.95 * (len(times) - 1) + 0.5)]  # the rank cvo_peers' StageTimer picks
    print(f"  frame {statistics.median(times):14.2f} {p95:8.2f}")


def rotation_to_quaternion(r):
    """x, y, z, w of a rotation matrix (Shepperd's method)."""
    w = np.sqrt(max(0.0, 1.0 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = np.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2
    y = np.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2
    z = np.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2
    x = np.copysign(x, r[2, 1] - r[1, 2])
    y = np.copysign(y, r[0, 2] - r[2, 0])
    z = np.copysign(z, r[1, 0] - r[0, 1])
    return x, y, z, w


if __name__ == "__main__":
    main()
