// The device path of the device backends, written once as Thrust algorithms over device vectors
// and built twice: by nvcc for a CUDA GPU (the `cuda` backend) and by the host compiler with
// THRUST_DEVICE_SYSTEM=THRUST_DEVICE_SYSTEM_OMP for OpenMP threads (device_pair_sums_omp.cpp, the
// `device_cpu` backend), so that every CI run executes the code a GPU runs. The per-point work is
// functors over the shared __host__ __device__ kernels (pair_kernels.hpp, dense_grid.hpp); what
// differs by system (execution policy, staging, the OpenMP reduction) is in cuda_system.cuh and
// omp_system.hpp.
//
// Parallelism: each source point's candidates are split between kLanesPerPoint lanes, lane l
// taking every kLanesPerPoint-th candidate of the point's stream of grid ranges from the l-th:
// on a GPU a warp then works on one point, its lanes reading consecutive target points (one
// thread a point left 15k threads each walking ~400 candidates in a row, latency-bound). A point's
// sums are linear in its pairs' (moments, Taylor terms, curvature), so the lanes' shares add up.
//
// Determinism: the grid is a stable sort (a unique order); each evaluation is one
// transform_reduce over the (source point, lane) items, whose order of additions is fixed for a
// given size:
// on CUDA by CUB's reduction (run to run on a device), on OpenMP by fixed chunks added in order
// (omp_system.hpp: the same bits for any thread count).
#include <thrust/binary_search.h>
#include <thrust/device_vector.h>
#include <thrust/gather.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/transform_iterator.h>
#include <thrust/sequence.h>
#include <thrust/sort.h>
#include <thrust/system_error.h>
#include <thrust/transform.h>
#include <thrust/transform_reduce.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "cvo_odometry/core/dense_grid.hpp"
#include "cvo_odometry/core/device_pair_sums.hpp"

#if THRUST_DEVICE_SYSTEM == THRUST_DEVICE_SYSTEM_CUDA
#include "cuda_system.cuh"
#elif THRUST_DEVICE_SYSTEM == THRUST_DEVICE_SYSTEM_OMP
#include "omp_system.hpp"
#else
#error "device_pair_sums: THRUST_DEVICE_SYSTEM must be CUDA or OMP"
#endif

namespace cvo {

namespace {

// The pose and twist travel inside the functors: no copy, no host wait per evaluation.
struct Pose3x4 {
  float m[12];
};
struct Twist {
  double v[6];
};

// Lanes a source point's candidates are split between (a warp on the GPU), the same on both
// systems so that device_cpu runs the GPU's arithmetic; a constant, so that item / lanes is a
// shift.
constexpr int kLanesPerPoint = 32;

struct CloudView {
  const float* positions;
  const float* colors;     // unused without colour
  const float* semantics;  // unused without semantics
};

// The rows of a cloud on the device that a subset's points are (CloudSubsets): every stride-th,
// or `count` rows spread over `total` (LabeledCloud::thinnedInto's, in the same 64-bit
// arithmetic).
struct SubsetRows {
  unsigned stride = 1;
  unsigned long long total = 0, count = 0;  // count 0: strided
  CVO_HOST_DEVICE unsigned row(unsigned k) const {
    return count ? static_cast<unsigned>(static_cast<unsigned long long>(k) * total / count)
                 : k * stride;
  }
};

// What every per-point functor reads: the target sorted by cell and its grid, the source, the
// pose and the kernels at this lengthscale.
struct PairContext {
  CloudView target, source;  // the target sorted by cell (its subset only), the whole source
  SubsetRows source_rows;
  kernels::DenseGridShape shape;
  const unsigned* start;  // first sorted point of every cell, then the point count
  float radius;           // the query radius: the cut-off at this lengthscale (<= the cell edge)
  float reach2;           // radius^2 and a margin: no pair beyond it can be retained
  Pose3x4 pose;
  kernels::KernelConstants k;
  float inv_two_ell2;
  double inv_ell2;

  // Source row `row` moved by the pose.
  CVO_HOST_DEVICE void moved(unsigned row, float* z) const {
    kernels::transformPoint(pose.m, source.positions + 3 * static_cast<std::size_t>(row), z);
  }

  // f(x, a) for lane `lane`'s share of the candidate target points x of source row j (at z)
  // that may be retained, with the pair's retained weight a (0 when not retained), in the grid's
  // fixed order: candidates lane, lane + kLanesPerPoint, ... of the point's ranges taken as one
  // stream. The ranges also hold points beyond the ball (weight 0, which adds nothing to any
  // sum): those are skipped before their appearance is computed.
  template <class F>
  CVO_HOST_DEVICE void forEachPair(unsigned row, int lane, const float* z, F&& f) const {
    const bool appearance = k.use_color || k.semantic_classes > 0;
    constexpr auto step = static_cast<unsigned>(kLanesPerPoint);
    unsigned skip = static_cast<unsigned>(lane);  // candidates before this lane's next one
    kernels::forEachRangeWithin(shape, start, z, radius, [&](unsigned begin, unsigned end) {
      if (end - begin <= skip) {
        skip -= end - begin;
        return;
      }
      unsigned i = begin + skip;
      for (; i < end; i += step) {
        const float* x = target.positions + 3 * i;
        const float dx = x[0] - z[0], dy = x[1] - z[1], dz = x[2] - z[2];
        if (dx * dx + dy * dy + dz * dz > reach2) continue;
        const float weight =
            appearance
                ? kernels::appearanceWeight(
                      k,
                      kernels::appearanceDistance2(
                          k, k.use_color ? target.colors + kernels::kColorDim * i : nullptr,
                          k.use_color ? source.colors + kernels::kColorDim * row : nullptr,
                          k.semantic_classes ? target.semantics + k.semantic_classes * i : nullptr,
                          k.semantic_classes ? source.semantics + k.semantic_classes * row
                                             : nullptr))
                : k.max_weight;  // = appearanceWeight(k, 0)
        f(x, kernels::retainedPairWeight(weight, dx, dy, dz, inv_two_ell2, k.sp_thres));
      }
      skip = i - end;
    });
  }

  // Adds lane `lane`'s share of source row `row`'s (at z) moments over its candidates to m.
  CVO_HOST_DEVICE void addMoments(unsigned row, int lane, const float* z,
                                  kernels::MomentSums& m) const {
    kernels::PointSums sums;
    kernels::clear(sums);
    forEachPair(row, lane, z, [&](const float* x, float a) {
      kernels::accumulatePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2]);
    });
    if (sums.pairs > 0) kernels::accumulatePoint(m, sums, z);
  }
};

// Item `item`'s share of an evaluation's sums: the subset's source point j = item /
// kLanesPerPoint (its row in the source) moved by the pose, then add(context, j, row, lane, z,
// sums) over that lane's candidates.
template <class Sums, class Add>
struct ShareOfPoint {
  PairContext c;
  Add add;
  CVO_HOST_DEVICE Sums operator()(int item) const {
    const int j = item / kLanesPerPoint, lane = item % kLanesPerPoint;
    const unsigned row = c.source_rows.row(static_cast<unsigned>(j));
    Sums sums;
    kernels::clear(sums);
    float z[3];
    c.moved(row, z);
    add(c, j, row, lane, z, sums);
    return sums;
  }
};

struct AddMoments {
  CVO_HOST_DEVICE void operator()(const PairContext& c, int, unsigned row, int lane, const float* z,
                                  kernels::MomentSums& m) const {
    c.addMoments(row, lane, z, m);
  }
};

struct AddTaylor {
  Twist xi;
  CVO_HOST_DEVICE void operator()(const PairContext& c, int, unsigned row, int lane, const float* z,
                                  kernels::TaylorSums& s) const {
    kernels::TaylorFrame frame;
    kernels::makeTaylorFrame(z, xi.v, frame);
    c.forEachPair(row, lane, z, [&](const float* x, float a) {
      if (a > 0.0f) kernels::accumulateTaylorPair(s, frame, x, z, a, c.inv_ell2);
    });
  }
};

// Moments over every source point, the Hessian from every kCurvatureStride-th of the subset
// (as the CPU).
struct AddCurvature {
  CVO_HOST_DEVICE void operator()(const PairContext& c, int j, unsigned row, int lane,
                                  const float* z, kernels::CurvatureSums& out) const {
    if (j % kernels::kCurvatureStride != 0) {
      c.addMoments(row, lane, z, out.moments);
      return;
    }
    kernels::PointCurvature sums;
    kernels::clear(sums);
    const float inv_shell_width = kernels::inverseShellWidth(c.k.sp_thres);
    c.forEachPair(row, lane, z, [&](const float* x, float a) {
      kernels::accumulateCurvaturePair(sums, a, x[0] - z[0], x[1] - z[1], x[2] - z[2], c.k.sp_thres,
                                       inv_shell_width);
    });
    kernels::accumulatePointCurvature(out, sums, z, c.inv_ell2, kernels::kCurvatureStride);
  }
};

template <class Sums>
struct AddSums {
  CVO_HOST_DEVICE Sums operator()(Sums a, const Sums& b) const {
    kernels::add(a, b);
    return a;
  }
};

// Grid build: the cell of the target subset's point i (row i * stride).
struct CellOfPoint {
  const float* positions;
  unsigned stride;
  kernels::DenseGridShape shape;
  CVO_HOST_DEVICE unsigned operator()(int i) const {
    return static_cast<unsigned>(kernels::cellOfPoint(
        shape, positions + 3 * static_cast<std::size_t>(static_cast<unsigned>(i) * stride)));
  }
};

// Element k of the sorted copy of a row-major array of `width` floats a point comes from
// element k % width of the row of subset point order[k / width] (row = point * stride).
struct SortedElement {
  const unsigned* order;
  unsigned width, stride;
  CVO_HOST_DEVICE std::size_t operator()(unsigned k) const {
    return static_cast<std::size_t>(order[k / width] * stride) * width + k % width;
  }
};

template <class T>
T* rawPointer(thrust::device_vector<T>& v) {
  return thrust::raw_pointer_cast(v.data());
}

// Grows v to at least n elements and never shrinks it: the storage is reused.
template <class T>
void grow(thrust::device_vector<T>& v, std::size_t n) {
  if (v.size() < n) v.resize(n);
}

// Runs f with the system's errors (CUDA errors, device memory) as std::runtime_error naming
// `what`, which FailoverBackend catches.
template <class F>
auto guarded(const char* what, F&& f) -> decltype(f()) {
  const std::string context = std::string(device::kSystemName) + " " + what + ": ";
  try {
    return f();
  } catch (const thrust::system_error& e) {
    throw std::runtime_error(context + e.what());
  } catch (const std::bad_alloc& e) {
    throw std::runtime_error(context + "out of device memory (" + e.what() + ")");
  }
}

}  // namespace

template <DeviceSystem System>
struct DevicePairSums<System>::Impl {
  static_assert(System == device::kSystem, "instantiated for the system it is compiled for");

  // Targets kept on the device (a keyframe is the target of every registration until the next,
  // the frames' self products come between) and grids kept per target (one per level).
  static constexpr int kTargetsKept = 2;
  static constexpr int kGridsPerTarget = 8;

  // A target subset sorted by grid cell, and each cell's first point: what the functors read.
  struct Grid {
    unsigned stride = 0;
    double radius = -1.0;  // the query radius it was built for; -1: none
    kernels::DenseGridShape shape{};
    thrust::device_vector<float> sorted[3];
    thrust::device_vector<unsigned> start;
    unsigned long long last_used = 0;
  };
  // A whole target cloud on the device, with the host's copy it came from (compared bit for bit
  // to know it again: a cloud changed in place, or a new one at a freed one's address, is
  // uploaded anew), and its grids.
  struct Target {
    bool valid = false;
    int count = 0, classes = 0;
    bool has_color = false;
    thrust::device_vector<float> uploaded[3];  // positions, colours, semantics
    std::vector<float> host[3];
    std::array<Grid, kGridsPerTarget> grids;
    unsigned long long last_used = 0;
  };

  explicit Impl(int threads) : runtime(threads) {}

  device::Runtime runtime;
  std::array<Target, kTargetsKept> targets;
  int target = 0;                               // the one in use
  thrust::device_vector<float> source[3];       // positions, colours, semantics
  thrust::device_vector<unsigned> cell, order;  // a grid build's scratch
  std::vector<float> strided_positions;         // a target subset's, for its bounding box
  int source_count = 0;                         // the whole source's points
  // The subsets (SubsetRows): the target's stride; the source's stride, or its thinned count.
  unsigned target_stride = 1, source_stride = 1;
  unsigned long long source_thinned = 0;
  int active_source = 0;  // the source subset's points
  kernels::KernelConstants constants{};
  double cutoff2 = 0.0;
  Grid* grid = nullptr;  // the grid of the last evaluation
  unsigned long long clock = 0;
  DeviceWork work;

  // The policy of one Thrust algorithm, counted.
  decltype(auto) policy() {
    ++work.algorithms;
    return runtime.policy();
  }

  // Makes the target with these arrays the one in use: a kept one when its bits are the same,
  // else uploaded in place of the least recently used.
  void useTarget(const float* const* host, const std::size_t* sizes, int count, int classes,
                 bool has_color) {
    for (int t = 0; t < kTargetsKept; ++t) {
      Target& kept = targets[t];
      if (!kept.valid || kept.count != count || kept.classes != classes ||
          kept.has_color != has_color) {
        continue;
      }
      bool same = true;
      for (int a = 0; a < 3 && same; ++a) {
        same = kept.host[a].size() == sizes[a] &&
               (sizes[a] == 0 ||
                std::memcmp(kept.host[a].data(), host[a], sizes[a] * sizeof(float)) == 0);
      }
      if (same) {
        target = t;
        kept.last_used = ++clock;
        return;
      }
    }
    int oldest = 0;
    for (int t = 1; t < kTargetsKept; ++t) {
      if (!targets[t].valid ||
          (targets[oldest].valid && targets[t].last_used < targets[oldest].last_used)) {
        oldest = t;
      }
    }
    Target& slot = targets[oldest];
    slot.valid = false;  // until the upload has succeeded
    for (Grid& g : slot.grids)
      g.radius = -1.0;
    float* destination[3];
    for (int a = 0; a < 3; ++a) {
      grow(slot.uploaded[a], sizes[a]);
      destination[a] = rawPointer(slot.uploaded[a]);
    }
    runtime.upload(3, host, sizes, destination);
    ++work.uploads;
    for (int a = 0; a < 3; ++a)
      slot.host[a].assign(host[a], host[a] + sizes[a]);
    slot.count = count;
    slot.classes = classes;
    slot.has_color = has_color;
    slot.valid = true;
    slot.last_used = ++clock;
    target = oldest;
  }

  // The grid of the target subset in use at `radius`: a kept one, else built in place of the
  // least recently used (the target sorted by cell: a stable sort of the cell indices, and each
  // cell's first point by binary searches, all on the device).
  Grid& gridFor(double radius) {
    Target& t = targets[target];
    Grid* slot = &t.grids[0];
    for (Grid& g : t.grids) {
      if (g.radius == radius && g.stride == target_stride) {
        g.last_used = ++clock;
        return g;
      }
      if (g.radius < 0.0 || (slot->radius >= 0.0 && g.last_used < slot->last_used)) slot = &g;
    }
    Grid& g = *slot;
    g.radius = -1.0;  // until it is built
    const int n = static_cast<int>((t.count + target_stride - 1) / target_stride);
    float lo[3], hi[3];
    if (target_stride == 1) {
      kernels::boundingBox(t.host[0].data(), static_cast<std::size_t>(n), lo, hi);
    } else {
      strided_positions.resize(3 * static_cast<std::size_t>(n));
      for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i)
        std::copy_n(&t.host[0][3 * i * target_stride], 3, &strided_positions[3 * i]);
      kernels::boundingBox(strided_positions.data(), static_cast<std::size_t>(n), lo, hi);
    }
    // Coarsen the cells when the box is huge (outdoor): still exact, just more points scanned.
    float edge = static_cast<float>(radius);
    double cells = kernels::shapeOverBox(lo, hi, edge, &g.shape);
    while (cells > kernels::kMaxDenseCells) {
      edge *= 1.5f;
      cells = kernels::shapeOverBox(lo, hi, edge, &g.shape);
    }
    const auto total = static_cast<std::size_t>(cells);
    grow(cell, n);
    grow(order, n);
    grow(g.start, total + 1);
    ++work.grid_builds;
    const thrust::counting_iterator<int> points(0);
    thrust::transform(policy(), points, points + n, cell.begin(),
                      CellOfPoint{rawPointer(t.uploaded[0]), target_stride, g.shape});
    thrust::sequence(policy(), order.begin(), order.begin() + n);
    thrust::stable_sort_by_key(policy(), cell.begin(), cell.begin() + n, order.begin());
    // start[c] = the first sorted point of cell c; start[total] = n.
    const thrust::counting_iterator<unsigned> cell_index(0);
    thrust::lower_bound(policy(), cell.begin(), cell.begin() + n, cell_index,
                        cell_index + (total + 1), g.start.begin());
    const int widths[3] = {3, t.has_color ? kernels::kColorDim : 0, t.classes};
    for (int a = 0; a < 3; ++a) {
      const std::size_t size = static_cast<std::size_t>(widths[a]) * n;
      grow(g.sorted[a], size);
      if (size == 0) continue;
      const auto element = thrust::make_transform_iterator(
          thrust::counting_iterator<unsigned>(0),
          SortedElement{rawPointer(order), static_cast<unsigned>(widths[a]), target_stride});
      thrust::gather(policy(), element, element + size, t.uploaded[a].begin(), g.sorted[a].begin());
    }
    g.stride = target_stride;
    g.radius = radius;
    g.last_used = ++clock;
    return g;
  }

  // The grid for `ell` and what the functors read.
  PairContext context(const float* pose, double ell) {
    const double radius = std::sqrt(cutoff2) * ell;
    if (!grid || grid->radius != radius || grid->stride != target_stride) grid = &gridFor(radius);
    PairContext c;
    c.target = {rawPointer(grid->sorted[0]), rawPointer(grid->sorted[1]),
                rawPointer(grid->sorted[2])};
    c.source = {rawPointer(source[0]), rawPointer(source[1]), rawPointer(source[2])};
    c.source_rows.stride = source_stride;
    c.source_rows.total = static_cast<unsigned long long>(source_count);
    c.source_rows.count = source_thinned;
    c.shape = grid->shape;
    c.start = rawPointer(grid->start);
    c.radius = static_cast<float>(radius);
    // Beyond reach2 a pair's weight is below sp_thres by a factor exp(-0.001) at least: far
    // more than rounding, so the skipped pairs are never retained ones.
    c.reach2 = static_cast<float>((cutoff2 + 0.002) * ell * ell);
    std::copy(pose, pose + 12, c.pose.m);
    c.k = constants;
    c.inv_two_ell2 = static_cast<float>(0.5 / (ell * ell));
    c.inv_ell2 = 1.0 / (ell * ell);
    return c;
  }

  // One transform_reduce over the (source point, lane) items, `add` giving each one's share at
  // (pose, ell); one wait, for the result.
  template <class Sums, class Add>
  Sums sumOverSource(const float* pose, double ell, const Add& add) {
    Sums zero;
    kernels::clear(zero);
    const thrust::counting_iterator<int> points(0);
    const int items = active_source * kLanesPerPoint;
    ++work.evaluations;
    return thrust::transform_reduce(policy(), points, points + items,
                                    ShareOfPoint<Sums, Add>{context(pose, ell), add}, zero,
                                    AddSums<Sums>{});
  }
};

template <DeviceSystem System>
DevicePairSums<System>::DevicePairSums(int threads) {
  guarded("set-up", [&] { impl_ = std::make_unique<Impl>(threads); });
}

template <DeviceSystem System>
DevicePairSums<System>::~DevicePairSums() = default;

template <DeviceSystem System>
void DevicePairSums<System>::setCloud(bool target, const float* positions, const float* colors,
                                      const float* semantics, int count, int classes) {
  guarded("upload", [&] {
    Impl& d = *impl_;
    const auto n = static_cast<std::size_t>(count);
    const float* host[3] = {positions, colors, semantics};
    const std::size_t sizes[3] = {3 * n, colors ? kernels::kColorDim * n : 0,
                                  semantics ? static_cast<std::size_t>(classes) * n : 0};
    d.grid = nullptr;
    if (target) {
      d.useTarget(host, sizes, count, classes, colors != nullptr);
    } else {
      float* destination[3];
      for (int a = 0; a < 3; ++a) {
        grow(d.source[a], sizes[a]);
        destination[a] = rawPointer(d.source[a]);
      }
      d.runtime.upload(3, host, sizes, destination);
      ++d.work.uploads;
      d.source_count = count;
    }
    // Every point of both, until useSubsets says otherwise.
    d.target_stride = d.source_stride = 1;
    d.source_thinned = 0;
    d.active_source = d.source_count;
  });
}

template <DeviceSystem System>
void DevicePairSums<System>::useSubsets(std::size_t target_stride, std::size_t source_stride,
                                        std::size_t source_count) {
  Impl& d = *impl_;
  const auto stride = static_cast<unsigned>(std::max<std::size_t>(target_stride, 1));
  d.target_stride = stride;
  const auto total = static_cast<std::size_t>(d.source_count);
  d.source_stride = 1;
  d.source_thinned = 0;
  std::size_t active = total;  // a count of every point or more: every point
  if (source_count != 0 && source_count < total) {
    d.source_thinned = source_count;
    active = source_count;
  } else if (source_count == 0) {
    d.source_stride = static_cast<unsigned>(std::max<std::size_t>(source_stride, 1));
    active = (total + d.source_stride - 1) / d.source_stride;
  }
  d.active_source = static_cast<int>(active);
}

template <DeviceSystem System>
void DevicePairSums<System>::setConstants(const kernels::KernelConstants& constants,
                                          double cutoff2) {
  impl_->constants = constants;
  impl_->cutoff2 = cutoff2;  // the grids are kept by radius, which holds the cut-off
}

template <DeviceSystem System>
kernels::MomentSums DevicePairSums<System>::moments(const float* pose, double ell) {
  return guarded("moments", [&] {
    return impl_->template sumOverSource<kernels::MomentSums>(pose, ell, AddMoments{});
  });
}

template <DeviceSystem System>
kernels::TaylorSums DevicePairSums<System>::taylor(const float* pose, const double* xi,
                                                   double ell) {
  return guarded("taylor", [&] {
    AddTaylor add;
    std::copy(xi, xi + 6, add.xi.v);
    return impl_->template sumOverSource<kernels::TaylorSums>(pose, ell, add);
  });
}

template <DeviceSystem System>
kernels::CurvatureSums DevicePairSums<System>::curvature(const float* pose, double ell) {
  return guarded("curvature", [&] {
    return impl_->template sumOverSource<kernels::CurvatureSums>(pose, ell, AddCurvature{});
  });
}

template <DeviceSystem System>
const DeviceWork& DevicePairSums<System>::work() const {
  return impl_->work;
}

template class DevicePairSums<device::kSystem>;

}  // namespace cvo
