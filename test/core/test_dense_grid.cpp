// The dense neighbour grid (dense_grid.hpp), whose arithmetic the CPU VoxelGrid and the CUDA
// kernels share: on a real TUM cloud every point within the radius is found, exactly once, and
// every point lands in a cell of the box; and the CPU backend's sums read from the grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "cvo_odometry/core/cell_hash_table.hpp"
#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/cvo_steps.hpp"
#include "cvo_odometry/core/dense_grid.hpp"
#include "cvo_odometry/core/voxel_grid.hpp"

namespace {

const std::string kCloud = std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame10_8000.cloud";

// Every point within `radius` of queries at (and just off) the cloud's points, exactly once; and
// anyWithin() says whether there is one, there and further off the cloud.
void expectExactNeighbours(const std::vector<float>& positions, std::size_t n, float cell,
                           float radius) {
  cvo::VoxelGrid grid;
  grid.build(positions.data(), n, cell);
  std::size_t pairs = 0, lone = 0;
  for (std::size_t q = 0; q < n; q += 37) {
    const float p[3] = {positions[3 * q] + 0.3f * radius, positions[3 * q + 1],
                        positions[3 * q + 2] - 0.2f * radius};
    std::multiset<std::uint32_t> found;
    grid.forEachWithin(p, radius, [&](std::uint32_t i, float) { found.insert(i); });
    std::multiset<std::uint32_t> expected;
    for (std::size_t i = 0; i < n; ++i) {
      const float dx = positions[3 * i] - p[0], dy = positions[3 * i + 1] - p[1],
                  dz = positions[3 * i + 2] - p[2];
      if (dx * dx + dy * dy + dz * dz <= radius * radius) {
        expected.insert(static_cast<std::uint32_t>(i));
      }
    }
    ASSERT_EQ(found, expected) << "cell " << cell << ", radius " << radius << ", query " << q;
    EXPECT_TRUE(grid.anyWithin(p, radius)) << "cell " << cell << ", query " << q;
    pairs += found.size();
    // anyWithin() off the cloud too, where a neighbour may or may not lie within the radius.
    const float off[3] = {p[0] + 1.2f * radius, p[1] - 0.9f * radius, p[2]};
    bool any = false;
    for (std::size_t i = 0; i < n && !any; ++i) {
      const float dx = positions[3 * i] - off[0], dy = positions[3 * i + 1] - off[1],
                  dz = positions[3 * i + 2] - off[2];
      any = dx * dx + dy * dy + dz * dz <= radius * radius;
    }
    ASSERT_EQ(grid.anyWithin(off, radius), any) << "cell " << cell << ", query " << q << " off";
    lone += any ? 0 : 1;
  }
  EXPECT_GT(lone, 0u) << "some queries off the cloud had no neighbour at radius " << radius;
  EXPECT_GT(pairs, n / 37) << "the queries found neighbours at radius " << radius;
}

TEST(DenseGrid, FindsExactlyTheNeighboursWithinTheRadius) {
  const cvo::LabeledCloud cloud = cvo::readCloud(kCloud);
  ASSERT_GT(cloud.size(), 7000u);
  for (const float radius : {0.03f, 0.1f, 0.4f}) {
    // The cell as large as the radius, smaller (the ball then spans several cells), and three
    // times larger (KeyframeOdometry's consistency grid).
    for (const float cells_per_radius : {1.0f, 2.0f, 3.0f, 1.0f / 3.0f}) {
      expectExactNeighbours(cloud.positionData(), cloud.size(), radius / cells_per_radius, radius);
    }
  }
}

TEST(DenseGrid, FindsTheNeighboursInAHashedGridToo) {
  // A point 5 km away makes the box too large for dense cells: the hash map serves instead.
  const cvo::LabeledCloud cloud = cvo::readCloud(kCloud);
  std::vector<float> positions = cloud.positionData();
  positions.insert(positions.end(), {5000.0f, -20.0f, 3000.0f});
  for (const float cells_per_radius : {1.0f, 2.0f}) {
    expectExactNeighbours(positions, cloud.size() + 1, 0.05f / cells_per_radius, 0.05f);
  }
}

TEST(CellHashTable, FindsEveryInsertedKeyAndNoOther) {
  // Keys of neighbouring cells along each axis (VoxelGrid's keys: z in bits 0-20, y 21-41, x
  // 42-62) and a dense run, with the table at its fullest (half): every probe chain must end
  // at the right slot or an empty one.
  cvo::CellHashTable table;
  std::vector<std::uint64_t> keys;
  for (std::uint64_t k = 0; k < 1000; ++k)
    keys.push_back(k << 21);
  for (std::uint64_t k = 1; k < 1000; ++k)
    keys.push_back(k << 42);
  for (std::uint64_t k = 0; k < 24; ++k)
    keys.push_back((std::uint64_t{1} << 62) + k);
  table.reset(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i)
    table.insert(keys[i], {static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(i + 1)});
  for (std::size_t i = 0; i < keys.size(); ++i) {
    const cvo::CellHashTable::Range* range = table.find(keys[i]);
    ASSERT_NE(range, nullptr) << "key " << keys[i];
    EXPECT_EQ(range->first, i);
    EXPECT_EQ(range->second, i + 1);
  }
  for (std::uint64_t k = 0; k < 1000; ++k) {
    EXPECT_EQ(table.find((k << 21) + 1), nullptr);
    EXPECT_EQ(table.find((k << 42) + 3), nullptr);
  }
  table.clear();
  EXPECT_EQ(table.find(keys[0]), nullptr);
}

TEST(DenseGrid, EveryPointOfTheBoxHasACell) {
  // A box whose far face lies exactly on a cell boundary: rounding must not leave the grid.
  const cvo::kernels::DenseGridShape shape{{-1.0f, 0.0f, 0.5f}, 0.1f, {20, 10, 30}};
  const float corners[][3] = {{-1.0f, 0.0f, 0.5f}, {1.0f, 1.0f, 3.5f}, {0.99999f, 0.5f, 3.5f}};
  const unsigned long long cells = 20ull * 10 * 30;
  for (const auto& p : corners)
    EXPECT_LT(cvo::kernels::cellOfPoint(shape, p), cells);
  EXPECT_EQ(cvo::kernels::cellOfPoint(shape, corners[0]), 0u);
  EXPECT_EQ(cvo::kernels::cellOfPoint(shape, corners[1]), cells - 1);
  // The ranges visited around far-away and non-finite points: none.
  std::vector<unsigned> start(cells + 1, 0);
  const float far[][3] = {{50.0f, 50.0f, 50.0f},
                          {-3e38f, 0.5f, 2.0f},
                          {0.5f, 1e38f, 2.0f},
                          {NAN, 0.5f, 2.0f},
                          {0.05f, 0.55f, INFINITY}};
  int ranges = 0;
  for (const auto& p : far) {
    cvo::kernels::forEachRangeWithin(shape, start.data(), p, 0.1f,
                                     [&](unsigned, unsigned) { ++ranges; });
  }
  EXPECT_EQ(ranges, 0);
  // Inside, a radius of one cell: at most the 3 x 3 columns around the point's own.
  const float inside[3] = {0.05f, 0.55f, 2.0f};
  cvo::kernels::forEachRangeWithin(shape, start.data(), inside, 0.1f,
                                   [&](unsigned, unsigned) { ++ranges; });
  EXPECT_GE(ranges, 1);
  EXPECT_LE(ranges, 9);
}

}  // namespace

namespace {

// The evaluations straight from the grid (one-off, and a coarse level's first evaluation with
// geometry only) against the candidate lists, on real clouds: the same sums up to float
// rounding, with and without colour, at poses the lists were not built for.
void expectSameSums(const cvo::kernels::MomentSums& a, const cvo::kernels::MomentSums& b,
                    const std::string& what) {
  EXPECT_EQ(a.pairs, b.pairs) << what;
  EXPECT_NEAR(b.weight, a.weight, 1e-5 * a.weight) << what;
  for (int k = 0; k < 9; ++k) {
    EXPECT_NEAR(b.cross[k], a.cross[k], 1e-5 * a.weight) << what << ", cross " << k;
  }
}

TEST(CpuBackendGridSums, MatchTheCandidateLists) {
  const cvo::LabeledCloud target =
      cvo::readCloud(std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame10_3000.cloud");
  const cvo::LabeledCloud source =
      cvo::readCloud(std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame11_3000.cloud");
  for (const bool color : {false, true}) {
    cvo::CvoParams params;
    params.use_color = color;
    params.ell_min = 0.05;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() << 0.01, -0.005, 0.008;
    T.linear() = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitY()).toRotationMatrix();
    for (const double ell : {0.05, 0.1}) {
      const std::string what =
          std::string(color ? "colour" : "geometry") + ", ell " + std::to_string(ell);
      cvo::CpuBackend lists(2), one_off(2);
      lists.setProblem(target, source, params);
      one_off.setProblem(target, source, params);
      // Above ell_min with geometry only, the first evaluation reads the grid, the second the
      // lists it then builds.
      const cvo::kernels::MomentSums first = lists.moments(T, ell);
      const cvo::kernels::MomentSums a = lists.moments(T, ell);
      ASSERT_GT(a.pairs, 500u) << what;
      expectSameSums(a, first, what + ", first evaluation");
      expectSameSums(a, one_off.oneOffMoments(T, ell), what + ", one-off");
      // With the lists built at T, a one-off evaluation near T reads them: identical sums.
      const cvo::kernels::MomentSums c = lists.oneOffMoments(T, ell);
      EXPECT_EQ(c.weight, a.weight) << what;
    }
  }
}

// One backend through problems of other sizes and targets (a registration's levels, its self
// products, the next frame's): its blocks and grids, kept from the earlier problems, give the
// sums a backend new to each problem gives.
TEST(CpuBackendReuse, SumsDoNotDependOnTheProblemsBefore) {
  const std::string clouds = std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/";
  const cvo::LabeledCloud large = cvo::readCloud(clouds + "frame11_8000.cloud");
  const cvo::LabeledCloud small = cvo::readCloud(clouds + "frame11_3000.cloud");
  const cvo::LabeledCloud keyframe = cvo::readCloud(clouds + "frame10_8000.cloud");
  ASSERT_GT(large.size(), 2 * small.size());
  cvo::CvoParams params;
  params.use_color = false;
  params.ell_min = 0.02;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() << 0.004, -0.002, 0.003;
  struct Problem {
    const cvo::LabeledCloud* target;
    const cvo::LabeledCloud* source;
    const char* name;
  };
  const Problem problems[] = {{&keyframe, &large, "keyframe <- large"},
                              {&small, &small, "small <- small"},
                              {&keyframe, &large, "keyframe <- large, again"},
                              {&large, &large, "large <- large"},
                              {&keyframe, &small, "keyframe <- small"}};
  cvo::CpuBackend reused(2);
  for (const Problem& problem : problems) {
    for (const double ell : {0.02, 0.05}) {
      const std::string what = std::string(problem.name) + ", ell " + std::to_string(ell);
      reused.setProblem(*problem.target, *problem.source, params);
      cvo::CpuBackend fresh(2);
      fresh.setProblem(*problem.target, *problem.source, params);
      const cvo::kernels::MomentSums a = reused.moments(T, ell);
      const cvo::kernels::MomentSums b = fresh.moments(T, ell);
      ASSERT_GT(b.pairs, 1000u) << what;
      EXPECT_EQ(a.pairs, b.pairs) << what;
      EXPECT_EQ(a.weight, b.weight) << what;
      const cvo::kernels::CurvatureSums c = reused.curvature(T, ell);
      const cvo::kernels::CurvatureSums d = fresh.curvature(T, ell);
      EXPECT_EQ(c.moments.weight, d.moments.weight) << what;
      for (int k = 0; k < 21; ++k)
        EXPECT_EQ(c.hessian[k], d.hessian[k]) << what << ", hessian " << k;
    }
  }
}

}  // namespace

namespace {

// The Newton step's Hessian (analytic, from every kCurvatureStride-th point, with the threshold's
// shell term) against central differences of the exact gradient, on real TUM clouds near
// alignment; and the moments that come with it equal the plain evaluation's.
TEST(CpuBackendCurvature, HessianMatchesDifferencesOfTheGradient) {
  const cvo::LabeledCloud target =
      cvo::readCloud(std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame10_8000.cloud");
  const cvo::LabeledCloud source =
      cvo::readCloud(std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/frame11_8000.cloud");
  cvo::CvoParams params;
  params.use_color = false;
  params.ell_min = 0.02;
  params.sp_thres = 0.003;
  const double ell = 0.02;
  cvo::CpuBackend backend(2);
  backend.setProblem(target, source, params);
  // Near the optimum (a registration's result, moved by 1 mm), where Newton steps are taken.
  params.newton_at_ell_min = false;
  cvo::CvoRegistration registration(params, std::make_unique<cvo::CpuBackend>(2));
  Eigen::Isometry3d T =
      registration.align(target, source, Eigen::Isometry3d::Identity(), false).transform;
  T.translation() += Eigen::Vector3d(0.001, -0.0005, 0.0005);
  backend.setProblem(target, source, params);
  const cvo::kernels::CurvatureSums c = backend.curvature(T, ell);
  const cvo::kernels::MomentSums m = backend.moments(T, ell);
  EXPECT_EQ(c.moments.pairs, m.pairs);
  EXPECT_NEAR(c.moments.weight, m.weight, 1e-6 * m.weight);
  Eigen::Matrix<double, 6, 6> analytic, differences;
  int slot = 0;
  for (int r = 0; r < 6; ++r) {
    for (int k = r; k < 6; ++k)
      analytic(r, k) = analytic(k, r) = c.hessian[slot++];
  }
  const double h = 2e-4;
  for (int k = 0; k < 6; ++k) {
    cvo::Vector6d e = cvo::Vector6d::Zero();
    e[k] = h;
    differences.col(k) =
        (cvo::objectiveGradient(backend.moments(cvo::lie::expSE3(e) * T, ell), ell) -
         cvo::objectiveGradient(backend.moments(cvo::lie::expSE3(-e) * T, ell), ell)) /
        (2.0 * h);
  }
  const Eigen::Matrix<double, 6, 6> symmetric = 0.5 * (differences + differences.transpose());
  const double error = (analytic - symmetric).norm() / symmetric.norm();
  EXPECT_LT(error, 0.15) << "analytic\n" << analytic << "\ndifferences\n" << symmetric;
  cvo::Vector6d step;
  ASSERT_TRUE(cvo::newtonStep(c, ell, &step)) << "negative definite near the optimum";
  const cvo::Vector6d reference = -symmetric.ldlt().solve(cvo::objectiveGradient(m, ell));
  EXPECT_GT(step.dot(reference) / (step.norm() * reference.norm()), 0.9);
}

}  // namespace
