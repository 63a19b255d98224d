// The device backends against the CPU backend. Every case runs on `device_cpu` (the device code,
// the same Thrust source as the CUDA backend's, on OpenMP threads) in every build that has it,
// CI's included, never skipped; and on `cuda` where a device is present (skipped with a message
// elsewhere). On synthetic rooms and real TUM frames, colour and geometric: free-running
// registrations (procrustes) agree within 1e-4 rad / 0.1 mm, the indicator within 1e-5 relative
// and the iterations within 1; in lockstep (both step methods, semantics) every evaluation's
// sums agree within 1e-5; the sums themselves agree; edge cases of the grid (empty, one point,
// growing and shrinking clouds, a huge bounding box); a device error (the CPU takes over).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cvo_odometry/core/backend_factory.hpp"
#include "cvo_odometry/core/cloud_io.hpp"
#include "cvo_odometry/core/cpu_backend.hpp"
#include "cvo_odometry/core/cvo_registration.hpp"
#include "cvo_odometry/core/device_backend.hpp"
#include "cvo_odometry/core/failover_backend.hpp"
#include "cvo_odometry/core/fault_injection_backend.hpp"
#include "cvo_odometry/core/timed_backend.hpp"
#include "synthetic_scene.hpp"

namespace {

using cvo::LabeledCloud;

// The device backend `which` ("device_cpu" or "cuda"), `threads` for device_cpu's reductions.
std::unique_ptr<cvo::RegistrationBackend> makeDevice(const std::string& which, int threads = 0) {
#ifdef CVO_HAVE_CUDA
  if (which == "cuda") return std::make_unique<cvo::CudaBackend>();
#endif
#ifdef CVO_HAVE_DEVICE_CPU
  if (which == "device_cpu") return std::make_unique<cvo::DeviceCpuBackend>(threads);
#endif
  (void)threads;
  throw std::logic_error("no backend " + which + " in this build");
}

std::vector<std::string> devicesOfThisBuild() {
  std::vector<std::string> devices;
#ifdef CVO_HAVE_DEVICE_CPU
  devices.push_back("device_cpu");
#endif
#ifdef CVO_HAVE_CUDA
  devices.push_back("cuda");
#endif
  return devices;
}

Eigen::Isometry3d motion(double angle, double tx, double ty, double tz) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2, 0.3, 1.0).normalized()).toRotationMatrix();
  T.translation() << tx, ty, tz;
  return T;
}

std::string tumFile(const std::string& name) {
  return std::string(CVO_TEST_DATA_DIR) + "/tum_clouds/" + name + ".cloud";
}

// Relative agreement of two sums (absolute below `floor`).
void expectClose(double device, double cpu, double relative, const std::string& what,
                 double floor = 1e-12) {
  EXPECT_NEAR(device, cpu, relative * std::max(std::abs(cpu), floor)) << what;
}

void expectSameMoments(const cvo::kernels::MomentSums& d, const cvo::kernels::MomentSums& c,
                       const std::string& what) {
  // Float sums per source point in another candidate order: a few 1e-7 relative.
  const double tol = 1e-5;
  expectClose(d.weight, c.weight, tol, what + " weight");
  for (int k = 0; k < 3; ++k) {
    expectClose(d.target[k], c.target[k], tol, what + " target", c.weight);
    expectClose(d.source[k], c.source[k], tol, what + " source", c.weight);
  }
  for (int k = 0; k < 9; ++k)
    expectClose(d.cross[k], c.cross[k], tol, what + " cross", c.weight);
  EXPECT_NEAR(static_cast<double>(d.pairs), static_cast<double>(c.pairs), 1e-5 * c.pairs) << what;
}

class DeviceTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    std::string why_not;
    if (GetParam() == "cuda" && !cvo::cudaBackendAvailable(&why_not)) GTEST_SKIP() << why_not;
  }
  std::unique_ptr<cvo::RegistrationBackend> device(int threads = 0) const {
    return makeDevice(GetParam(), threads);
  }
};

std::string deviceName(const ::testing::TestParamInfo<std::string>& info) {
  return info.param;
}

// --- Registrations -----------------------------------------------------------------------

struct ParityCase {
  std::string name;
  bool real;   // TUM frames 10 -> 11, else the synthetic room under a known motion
  int points;  // TUM: 3000 or 15000 (the fixture's sizes)
  bool color;
  int classes;  // semantic classes (synthetic only), 0: none
  cvo::StepMethod method;
  int iteration_slack = 1;  // free-running: iterations within this of the CPU's
};

void PrintTo(const ParityCase& c, std::ostream* os) {
  *os << c.name;
}

struct Problem {
  cvo::CvoParams params;
  LabeledCloud target, source;
  bool first_frame = false;
};

Problem problemOf(const ParityCase& c) {
  Problem p;
  p.params.use_color = c.color;
  p.params.step_method = c.method;
  if (c.real) {
    p.target = cvo::readCloud(tumFile("frame10_" + std::to_string(c.points)));
    p.source = cvo::readCloud(tumFile("frame11_" + std::to_string(c.points)));
    return p;
  }
  p.params.ell_first_frame = 0.5;
  p.first_frame = true;
  if (c.classes) {
    p.params.use_semantics = true;
    p.params.semantic_cross_weight = 0.5;  // cross-class pairs count too, at half weight
    p.params.semantic_sigma = 1.0;
  }
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  truth.translation() << 0.1, -0.05, 0.02;
  p.target = cvo_test::roomScene(c.points, 10, c.color, c.classes);
  p.source = cvo_test::roomScene(c.points, 11, c.color, c.classes)
                 .transformed(truth.inverse().cast<float>());
  return p;
}

std::string methodName(cvo::StepMethod method) {
  return method == cvo::StepMethod::kReference ? "Reference" : "Procrustes";
}

// Free-running registrations: the procrustes method (the default), whose result is a stable
// function of the sums. The reference method's is not: it anneals when a ratio of retained-pair
// counts crosses a threshold and stops at eps_2 at whatever lengthscale it has reached, so the
// CPU against itself, its sums scaled by 1 +- 1e-12, ends 1.4e-4 rad / 0.54 mm apart on the TUM
// frames, at another lengthscale (indicator 16 % apart). It is compared in lockstep.
std::vector<ParityCase> freeRunningCases() {
  std::vector<ParityCase> cases;
  for (bool color : {false, true}) {
    const std::string kernels = color ? "Colour" : "Geometric";
    const auto procrustes = cvo::StepMethod::kProcrustes;
    // The synthetic room with colour ends a few iterations apart whenever its sums change in
    // the last bits (measured: the CPU against itself, its sums scaled by 1 +- 1e-12, 31 vs 27
    // iterations; the same transform within 1e-7): its iteration count is no parity test.
    cases.push_back({"SyntheticRoom" + kernels, false, 3000, color, 0, procrustes, color ? 5 : 1});
    cases.push_back({"Tum3000" + kernels, true, 3000, color, 0, procrustes});
    cases.push_back({"Tum15000" + kernels, true, 15000, color, 0, procrustes});
  }
  return cases;
}

// Lockstep: both step methods, every evaluation of the registration compared. The synthetic
// room for the reference method at 600 points (its coarse first-frame levels pair every point
// with every other: minutes on the CPU at 3000); the reference method at 15k likewise skipped.
std::vector<ParityCase> lockstepCases() {
  std::vector<ParityCase> cases;
  for (auto method : {cvo::StepMethod::kProcrustes, cvo::StepMethod::kReference}) {
    const bool reference = method == cvo::StepMethod::kReference;
    for (bool color : {false, true}) {
      const std::string name = std::string(color ? "Colour" : "Geometric") + methodName(method);
      cases.push_back({"SyntheticRoom" + name, false, reference ? 600 : 3000, color, 0, method});
      cases.push_back({"Tum3000" + name, true, 3000, color, 0, method});
      if (!reference) cases.push_back({"Tum15000" + name, true, 15000, color, 0, method});
    }
  }
  cases.push_back(
      {"SyntheticRoomSemanticsProcrustes", false, 2000, true, 3, cvo::StepMethod::kProcrustes});
  return cases;
}

using DeviceAndCase = std::tuple<std::string, ParityCase>;

std::string caseName(const ::testing::TestParamInfo<DeviceAndCase>& info) {
  return std::get<0>(info.param) + "_" + std::get<1>(info.param).name;
}

class RegistrationParity : public ::testing::TestWithParam<DeviceAndCase> {
 protected:
  void SetUp() override {
    std::string why_not;
    if (std::get<0>(GetParam()) == "cuda" && !cvo::cudaBackendAvailable(&why_not)) {
      GTEST_SKIP() << why_not;
    }
  }
};

// The device's registration against the CPU's: transform within 1e-4 rad / 0.1 mm, indicator
// within 5e-5 relative (it is taken at the two final poses, which differ by float summation
// order; LockstepParity compares evaluations at one pose), iterations within 1 (but see
// freeRunningCases).
TEST_P(RegistrationParity, SameRegistrationAsTheCpu) {
  const auto& [which, c] = GetParam();
  const Problem p = problemOf(c);
  cvo::CvoRegistration cpu(p.params, std::make_unique<cvo::CpuBackend>());
  cvo::CvoRegistration dev(p.params, makeDevice(which));
  const auto a = cpu.align(p.target, p.source, Eigen::Isometry3d::Identity(), p.first_frame);
  const auto b = dev.align(p.target, p.source, Eigen::Isometry3d::Identity(), p.first_frame);
  EXPECT_EQ(b.report.backend, which);
  EXPECT_TRUE(b.report.converged) << b.report.message;
  const Eigen::Isometry3d diff = a.transform.inverse() * b.transform;
  EXPECT_LT(cvo::lie::rotationAngle(diff.linear()), 1e-4);
  EXPECT_LT(diff.translation().norm(), 1e-4);
  EXPECT_NEAR(b.report.indicator_after, a.report.indicator_after, 5e-5 * a.report.indicator_after);
  // Float sums in another order may move the last step across eps_2 one iteration apart.
  EXPECT_LE(std::abs(a.report.iterations - b.report.iterations), c.iteration_slack)
      << a.report.iterations << " vs " << b.report.iterations;
}

INSTANTIATE_TEST_SUITE_P(Devices, RegistrationParity,
                         ::testing::Combine(::testing::ValuesIn(devicesOfThisBuild()),
                                            ::testing::ValuesIn(freeRunningCases())),
                         caseName);

// Forwards every call to the CPU backend and to the device backend, compares the device's sums
// with the CPU's and returns the CPU's, so that the registration takes the CPU's path and every
// evaluation along it (each lengthscale's grid, the subsampled coarse clouds, one-off sums,
// Taylor and curvature sums) is checked, free of the path's sensitivity to rounding.
class Lockstep : public cvo::RegistrationBackend {
 public:
  explicit Lockstep(std::unique_ptr<cvo::RegistrationBackend> device)
      : device_(std::move(device)) {}

  std::string name() const override { return "lockstep"; }
  void setProblem(const LabeledCloud& target, const LabeledCloud& source,
                  const cvo::CvoParams& params) override {
    cpu_.setProblem(target, source, params);
    device_->setProblem(target, source, params);
  }
  void useSubsets(const cvo::CloudSubsets& subsets) override {
    cpu_.useSubsets(subsets);
    device_->useSubsets(subsets);
  }
  cvo::kernels::MomentSums moments(const Eigen::Isometry3d& T, double ell) override {
    const auto c = cpu_.moments(T, ell);
    compare(device_->moments(T, ell), c, "moments", ell);
    return c;
  }
  cvo::kernels::MomentSums oneOffMoments(const Eigen::Isometry3d& T, double ell) override {
    const auto c = cpu_.oneOffMoments(T, ell);
    compare(device_->oneOffMoments(T, ell), c, "one-off moments", ell);
    return c;
  }
  cvo::kernels::TaylorSums taylor(const Eigen::Isometry3d& T, const cvo::Vector6d& xi,
                                  double ell) override {
    ++taylor_calls;
    const auto c = cpu_.taylor(T, xi, ell);
    const auto d = device_->taylor(T, xi, ell);
    const double scale = std::abs(c.b) + std::abs(c.c) + std::abs(c.d) + std::abs(c.e);
    const double values[4][2] = {{d.b, c.b}, {d.c, c.c}, {d.d, c.d}, {d.e, c.e}};
    for (const auto& v : values)
      note(v[0], v[1], scale, "taylor", ell);
    return c;
  }
  cvo::kernels::CurvatureSums curvature(const Eigen::Isometry3d& T, double ell) override {
    ++curvature_calls;
    const auto c = cpu_.curvature(T, ell);
    const auto d = device_->curvature(T, ell);
    compare(d.moments, c.moments, "curvature moments", ell);
    double scale = 0.0;
    for (double h : c.hessian)
      scale = std::max(scale, std::abs(h));
    for (int k = 0; k < 21; ++k)
      note(d.hessian[k], c.hessian[k], scale, "hessian", ell);
    return c;
  }

  int moment_calls = 0, taylor_calls = 0, curvature_calls = 0;
  double worst = 0.0;  // largest relative difference of a sum
  std::string worst_where;
  double worst_pairs = 0.0;  // largest relative difference of a retained-pair count
  std::string worst_pairs_where;

 private:
  std::string where(const char* what, double ell) const {
    return std::string(what) + " (evaluation " +
           std::to_string(moment_calls + taylor_calls + curvature_calls) + ", ell " +
           std::to_string(ell) + ")";
  }
  void note(double device, double cpu, double scale, const char* what, double ell) {
    const double difference = std::abs(device - cpu) / std::max(scale, 1e-300);
    if (difference > worst) {
      worst = difference;
      worst_where = where(what, ell) + ": " + std::to_string(device) + " vs " + std::to_string(cpu);
    }
  }
  void compare(const cvo::kernels::MomentSums& d, const cvo::kernels::MomentSums& c,
               const char* what, double ell) {
    ++moment_calls;
    note(d.weight, c.weight, std::abs(c.weight), what, ell);
    double target = 0.0, source = 0.0, cross = 0.0;
    for (int k = 0; k < 3; ++k) {
      target = std::max(target, std::abs(c.target[k]));
      source = std::max(source, std::abs(c.source[k]));
    }
    for (double v : c.cross)
      cross = std::max(cross, std::abs(v));
    for (int k = 0; k < 3; ++k) {
      note(d.target[k], c.target[k], target, what, ell);
      note(d.source[k], c.source[k], source, what, ell);
    }
    for (int k = 0; k < 9; ++k)
      note(d.cross[k], c.cross[k], cross, what, ell);
    const double pairs = std::abs(static_cast<double>(d.pairs) - static_cast<double>(c.pairs)) /
                         std::max<double>(static_cast<double>(c.pairs), 1.0);
    if (pairs > worst_pairs) {
      worst_pairs = pairs;
      worst_pairs_where =
          where(what, ell) + ": " + std::to_string(d.pairs) + " vs " + std::to_string(c.pairs);
    }
  }

  cvo::CpuBackend cpu_;
  std::unique_ptr<cvo::RegistrationBackend> device_;
};

class LockstepParity : public RegistrationParity {};

// Every evaluation of the registration: sums within 1e-5 relative of the CPU's (the scale of a
// sum: the largest of its group), retained-pair counts within 1e-5 relative (a pair right at
// sp_thres may flip where one side fuses multiply-adds: the CPU's AVX-512 path, a GPU).
TEST_P(LockstepParity, EveryEvaluationMatchesTheCpu) {
  const auto& [which, c] = GetParam();
  const Problem p = problemOf(c);
  auto lockstep = std::make_unique<Lockstep>(makeDevice(which));
  const Lockstep& watch = *lockstep;
  cvo::CvoRegistration registration(p.params, std::move(lockstep));
  const auto result =
      registration.align(p.target, p.source, Eigen::Isometry3d::Identity(), p.first_frame);
  EXPECT_TRUE(result.report.converged) << result.report.message;
  EXPECT_GE(watch.moment_calls, result.report.iterations);
  const bool reference = c.method == cvo::StepMethod::kReference;
  EXPECT_GT(reference ? watch.taylor_calls : watch.curvature_calls, 0);
  EXPECT_LT(watch.worst, 1e-5) << watch.worst_where;
  EXPECT_LT(watch.worst_pairs, 1e-5) << watch.worst_pairs_where;
  std::cout << "    " << watch.moment_calls << " moment, " << watch.taylor_calls << " Taylor, "
            << watch.curvature_calls << " curvature evaluations; worst relative difference "
            << watch.worst << ", of retained pairs " << watch.worst_pairs << "\n";
}

INSTANTIATE_TEST_SUITE_P(Devices, LockstepParity,
                         ::testing::Combine(::testing::ValuesIn(devicesOfThisBuild()),
                                            ::testing::ValuesIn(lockstepCases())),
                         caseName);

// --- The sums ----------------------------------------------------------------------------

// Moments, Taylor and curvature sums of the real frames at a few poses and lengthscales (one
// grid per lengthscale, coarse and fine) against the CPU backend's.
TEST_P(DeviceTest, SumsMatchTheCpu) {
  const LabeledCloud target = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud source = cvo::readCloud(tumFile("frame11_3000"));
  for (bool color : {false, true}) {
    cvo::CvoParams params;
    params.use_color = color;
    cvo::CpuBackend cpu(1);
    auto dev = device();
    cpu.setProblem(target, source, params);
    dev->setProblem(target, source, params);
    for (double ell : {0.2, 0.05, params.ell_min}) {
      for (const auto& T : {Eigen::Isometry3d::Identity(), motion(0.01, 0.005, -0.01, 0.003)}) {
        const std::string what =
            std::string(color ? "colour" : "geometric") + " ell " + std::to_string(ell);
        expectSameMoments(dev->moments(T, ell), cpu.moments(T, ell), what + " moments");
        cvo::Vector6d xi;
        xi << 0.01, -0.02, 0.005, 0.03, 0.01, -0.02;
        const auto td = dev->taylor(T, xi, ell), tc = cpu.taylor(T, xi, ell);
        const double scale = std::abs(tc.b) + std::abs(tc.c) + std::abs(tc.d) + std::abs(tc.e);
        for (const auto& [d, c] : {std::pair{td.b, tc.b}, {td.c, tc.c}, {td.d, tc.d}, {td.e, tc.e}})
          EXPECT_NEAR(d, c, 1e-5 * scale) << what << " taylor";
        const auto cd = dev->curvature(T, ell), cc = cpu.curvature(T, ell);
        expectSameMoments(cd.moments, cc.moments, what + " curvature moments");
        double hessian_scale = 0.0;
        for (double h : cc.hessian)
          hessian_scale = std::max(hessian_scale, std::abs(h));
        for (int k = 0; k < 21; ++k)
          EXPECT_NEAR(cd.hessian[k], cc.hessian[k], 1e-5 * hessian_scale)
              << what << " hessian " << k;
      }
    }
  }
}

// The device work counted per call matches the calls a registration makes (cvo_benchmark
// --time-calls prints it per registration): one reduction and one wait per evaluation, one upload
// per cloud a problem sets, and each grid build's algorithms.
TEST_P(DeviceTest, DeviceWorkCountsTheRegistrationsCalls) {
  const LabeledCloud target = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud source = cvo::readCloud(tumFile("frame11_3000"));
  cvo::CvoParams params;
  params.use_color = true;
  auto timed_backend = std::make_unique<cvo::TimedBackend>(device());
  const cvo::TimedBackend& timed = *timed_backend;
  ASSERT_TRUE(timed.deviceWork());
  const cvo::DeviceWork before = *timed.deviceWork();
  EXPECT_EQ(before.algorithms, 0);
  cvo::CvoRegistration registration(params, std::move(timed_backend));
  const auto result = registration.align(target, source, Eigen::Isometry3d::Identity());
  ASSERT_TRUE(result.report.converged);
  const cvo::DeviceWork work = *timed.deviceWork();
  using Call = cvo::TimedBackend::Call;
  const long evaluations = timed.tally(Call::kMoments).calls +
                           timed.tally(Call::kOneOffMoments).calls +
                           timed.tally(Call::kTaylor).calls + timed.tally(Call::kCurvature).calls;
  EXPECT_GT(evaluations, 0);
  EXPECT_EQ(work.evaluations, evaluations);
  // The clouds are copied once (target and source); the levels are subsets of them on the device.
  EXPECT_EQ(timed.tally(Call::kSetProblem).calls, 1);
  EXPECT_EQ(work.uploads, 2);
  EXPECT_GE(timed.tally(Call::kUseSubsets).calls, 2);
  EXPECT_GE(work.grid_builds, 2);
  EXPECT_LE(work.grid_builds, evaluations);
  // A grid build: cells, sequence, sort, cell starts and a gather per array (positions, colours).
  EXPECT_EQ(work.algorithms, work.evaluations + 6 * work.grid_builds);
}

// A keyframe is the target of every frame's registration, with the frames' self products in
// between: kept on the device with its grids, it is uploaded once; a cloud changed in place is
// uploaded again. Every result is a fresh backend's, bit for bit.
TEST_P(DeviceTest, AKeptTargetIsUploadedOnceAndAChangedOneAgain) {
  LabeledCloud target = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud source = cvo::readCloud(tumFile("frame11_3000"));
  const LabeledCloud moved =
      source.transformed(Eigen::Isometry3f(Eigen::Translation3f(0.01f, -0.005f, 0.0f)));
  cvo::CvoParams params;
  params.use_color = true;
  auto timed_backend = std::make_unique<cvo::TimedBackend>(device());
  const cvo::TimedBackend& timed = *timed_backend;
  cvo::CvoRegistration kept(params, std::move(timed_backend));
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const auto fresh = [&](const LabeledCloud& t, const LabeledCloud& s) {
    cvo::CvoRegistration registration(params, device());
    return registration.align(t, s, I).transform;
  };

  EXPECT_TRUE(kept.align(target, source, I).transform.matrix() == fresh(target, source).matrix());
  const cvo::DeviceWork first = *timed.deviceWork();
  EXPECT_EQ(first.uploads, 2);
  EXPECT_GE(first.grid_builds, 2);
  kept.selfProduct(source, params.ell_min);  // another target, as the odometry's cosine sets
  const cvo::DeviceWork between = *timed.deviceWork();
  EXPECT_EQ(between.uploads - first.uploads, 2);

  EXPECT_TRUE(kept.align(target, moved, I).transform.matrix() == fresh(target, moved).matrix());
  const cvo::DeviceWork second = *timed.deviceWork();
  EXPECT_EQ(second.uploads - between.uploads, 1) << "the source only: the target is kept";
  EXPECT_LT(second.grid_builds - between.grid_builds, first.grid_builds)
      << "the levels' grids of the kept target are kept";

  target = moved;  // the same object and size, other bits
  EXPECT_TRUE(kept.align(target, source, I).transform.matrix() == fresh(target, source).matrix());
  const cvo::DeviceWork changed = *timed.deviceWork();
  EXPECT_EQ(changed.uploads - second.uploads, 2) << "a target changed in place is uploaded again";
  EXPECT_GE(changed.grid_builds - second.grid_builds, 1);
}

TEST_P(DeviceTest, EmptyAndSinglePointClouds) {
  cvo::CvoParams params;
  const LabeledCloud empty(true, 0);
  LabeledCloud one(true, 0);
  cvo_test::addPoint(one, {0.1f, 0.2f, 0.3f});
  const LabeledCloud room = cvo_test::roomScene(500, 1);
  auto dev = device();
  cvo::CpuBackend cpu(1);
  for (const auto& [target, source] :
       {std::pair{&empty, &room}, {&room, &empty}, {&one, &one}, {&one, &room}, {&room, &one}}) {
    dev->setProblem(*target, *source, params);
    cpu.setProblem(*target, *source, params);
    expectSameMoments(dev->moments(Eigen::Isometry3d::Identity(), 0.1),
                      cpu.moments(Eigen::Isometry3d::Identity(), 0.1),
                      std::to_string(target->size()) + " <- " + std::to_string(source->size()));
  }
  dev->setProblem(one, one, params);
  EXPECT_EQ(dev->moments(Eigen::Isometry3d::Identity(), 0.1).pairs, 1u) << "a point pairs itself";
}

// One backend through problems of changing sizes gives what a fresh one gives: buffers that
// grow and stay large must not leak old points into smaller problems.
TEST_P(DeviceTest, BuffersGrowAndShrinkBetweenProblems) {
  cvo::CvoParams params;
  params.use_color = true;
  const LabeledCloud small_t = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud small_s = cvo::readCloud(tumFile("frame11_3000"));
  const LabeledCloud large_t = cvo::readCloud(tumFile("frame10_15000"));
  const LabeledCloud large_s = cvo::readCloud(tumFile("frame11_15000"));
  auto reused = device();
  const Eigen::Isometry3d T = motion(0.005, 0.002, 0.0, -0.003);
  for (const auto& [target, source] : {std::pair{&small_t, &small_s},
                                       {&large_t, &large_s},
                                       {&small_t, &large_s},
                                       {&large_t, &small_s},
                                       {&small_t, &small_s}}) {
    reused->setProblem(*target, *source, params);
    auto fresh = device();
    fresh->setProblem(*target, *source, params);
    for (double ell : {0.1, params.ell_min}) {
      const auto a = reused->moments(T, ell), b = fresh->moments(T, ell);
      const std::string what = std::to_string(target->size()) + " <- " +
                               std::to_string(source->size()) + " ell " + std::to_string(ell);
      EXPECT_EQ(a.weight, b.weight) << what;
      EXPECT_EQ(a.pairs, b.pairs) << what;
    }
  }
}

// A far outlier stretches the bounding box past the dense grid's cell budget: the device grid
// coarsens its cells and must still find every pair.
TEST_P(DeviceTest, HugeBoundingBoxCoarsensTheGrid) {
  cvo::CvoParams params;
  LabeledCloud target = cvo_test::roomScene(1500, 5, true);
  cvo_test::addPoint(target, {400.0f, -300.0f, 250.0f});
  const LabeledCloud source = cvo_test::roomScene(1500, 6, true);
  cvo::CpuBackend cpu(1);
  auto dev = device();
  cpu.setProblem(target, source, params);
  dev->setProblem(target, source, params);
  for (double ell : {0.3, 0.05})
    expectSameMoments(dev->moments(Eigen::Isometry3d::Identity(), ell),
                      cpu.moments(Eigen::Isometry3d::Identity(), ell),
                      "huge box, ell " + std::to_string(ell));
}

// --- Failures ----------------------------------------------------------------------------

// A device error mid-registration (injected after 5 evaluations): the CPU replays the call and
// finishes the registration with the CPU's answer, the report says so; the next registration
// tries the device again.
TEST_P(DeviceTest, ADeviceErrorFallsBackToTheCpu) {
  cvo::CvoParams params;
  const LabeledCloud target = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud source = cvo::readCloud(tumFile("frame11_3000"));
  auto failover = std::make_unique<cvo::FailoverBackend>(
      std::make_unique<cvo::FaultInjectionBackend>(device(), 5),
      std::make_unique<cvo::CpuBackend>());
  const cvo::FailoverBackend& watch = *failover;
  cvo::CvoRegistration flaky(params, std::move(failover));
  cvo::CvoRegistration cpu(params, std::make_unique<cvo::CpuBackend>());
  const auto expected = cpu.align(target, source, Eigen::Isometry3d::Identity());
  const auto got = flaky.align(target, source, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(got.report.converged);
  EXPECT_EQ(got.report.backend, "cpu (fallback: " + GetParam() + " (fault injection) failed)");
  EXPECT_NE(got.report.warning.find("injected backend fault"), std::string::npos);
  const Eigen::Isometry3d diff = expected.transform.inverse() * got.transform;
  EXPECT_LT(cvo::lie::rotationAngle(diff.linear()), 1e-4);
  EXPECT_LT(diff.translation().norm(), 1e-4);
  EXPECT_EQ(watch.failures(), 1);
  flaky.align(target, source, Eigen::Isometry3d::Identity());
  EXPECT_EQ(watch.failures(), 2) << "the next registration tried the device again";
}

INSTANTIATE_TEST_SUITE_P(Devices, DeviceTest, ::testing::ValuesIn(devicesOfThisBuild()),
                         deviceName);
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(DeviceTest);

}  // namespace

// --- device_cpu only ---------------------------------------------------------------------

#ifdef CVO_HAVE_DEVICE_CPU
// The OpenMP reduction is over fixed chunks added in order: the same bits on any thread count.
TEST(DeviceCpu, SameBitsOnAnyThreadCount) {
  cvo::CvoParams params;
  params.use_color = true;
  const LabeledCloud target = cvo::readCloud(tumFile("frame10_3000"));
  const LabeledCloud source = cvo::readCloud(tumFile("frame11_3000"));
  cvo::RegistrationResult first;
  // Not 7: LLVM 14's libomp leaks a thread team when 7 threads follow fewer (LeakSanitizer;
  // reproduced without Thrust).
  for (int threads : {1, 2, 3, 4}) {
    cvo::CvoRegistration registration(params, std::make_unique<cvo::DeviceCpuBackend>(threads));
    const auto result = registration.align(target, source, Eigen::Isometry3d::Identity());
    if (threads == 1) {
      first = result;
      continue;
    }
    EXPECT_EQ(result.transform.matrix(), first.transform.matrix()) << threads << " threads";
    EXPECT_EQ(result.report.indicator_after, first.report.indicator_after) << threads;
    EXPECT_EQ(result.report.iterations, first.report.iterations) << threads;
  }
}

TEST(DeviceCpu, IsABackendChoice) {
  EXPECT_EQ(cvo::parseBackendChoice("device_cpu"), cvo::BackendChoice::kDeviceCpu);
  EXPECT_EQ(cvo::toString(cvo::BackendChoice::kDeviceCpu), "device_cpu");
  EXPECT_EQ(cvo::makeBackend(cvo::BackendChoice::kDeviceCpu, 1)->name(), "device_cpu");
}
#endif
