// The per-pair arithmetic of CVO, written once for the CPU backend and the CUDA kernels
// (compiled as __host__ __device__ by nvcc). No Eigen or STL here: plain floats and doubles.
//
// Pair weight of target point x_i and moved source point z_j:
//   a_ij = s^2 exp(-|x_i - z_j|^2 / (2 ell^2)) * s_c^2 exp(-|c_i - c_j|^2 / (2 ell_c^2))
//          * s_s^2 (w + (1 - w) cos(p_i, p_j))
// (colour c, class probabilities p, cross-class weight w; a factor only when its kernel is on)
// and the pair counts (is "retained") only when a_ij > sp_thres.
#pragma once

#include <math.h>

#if defined(__CUDACC__)
#define CVO_HOST_DEVICE __host__ __device__
#else
#define CVO_HOST_DEVICE
#endif

namespace cvo {
namespace kernels {

constexpr int kColorDim = 5;

// Kernel settings for one registration, copied by value to the device.
struct KernelConstants {
  float max_weight;  // s^2 * s_c^2 * s_s^2 over the kernels in use
  float sp_thres;
  int use_color;                // 0 or 1
  float color_inv_ell2;         // 1 / ell_c^2
  int semantic_classes;         // 0: semantics off
  float semantic_cross_weight;  // w: two points of different classes weigh w of a same-class pair
};

// Sums over retained pairs with the source moved by the current estimate: enough for F, its
// se(3) gradient and the weighted Procrustes step.
struct MomentSums {
  double weight;     // F = sum a
  double target[3];  // sum a x
  double source[3];  // sum a z
  double cross[9];   // sum a x z^T, row-major
  unsigned long long pairs;
};

// Coefficients of F(exp(t xi) T) ~ F0 + B t + C t^2 + D t^3 + E t^4 (reference step).
struct TaylorSums {
  double b, c, d, e;
};

// Per-source-point partial sums over its neighbours, in float (a few hundred terms at most):
// sum a and sum a (x - z), the offsets being small keeps the float sums accurate.
struct PointSums {
  float weight;
  float offset[3];
  unsigned int pairs;
};

// For the Newton step at the finest lengthscale: the moments over every source point and the
// Hessian of G(exp(xi) T) = sum (a - sp_thres)_+ at xi = 0 (twist [omega; v]) estimated from every
// kCurvatureStride-th source point (scaled up; a step metric needs no more), upper triangle row
// by row (21 values). The gradient comes from the moments (objectiveGradient).
constexpr int kCurvatureStride = 4;
struct CurvatureSums {
  MomentSums moments;
  double hessian[21];
};

// Per-source-point sums for CurvatureSums, in float: sum a, sum a d, sum a d d^T (upper
// triangle: xx, xy, xz, yy, yz, zz), d = x - z, and over the pairs just above the threshold
// (the shell sp_thres < a < sp_thres + shell_width) sum a^2 d d^T / shell_width.
struct PointCurvature {
  float weight;
  float offset[3];
  float outer[6];
  float shell[6];
  unsigned int pairs;
};

CVO_HOST_DEVICE inline void clear(MomentSums& m) {
  m.weight = 0.0;
  for (int k = 0; k < 3; ++k)
    m.target[k] = m.source[k] = 0.0;
  for (int k = 0; k < 9; ++k)
    m.cross[k] = 0.0;
  m.pairs = 0;
}

CVO_HOST_DEVICE inline void add(MomentSums& m, const MomentSums& o) {
  m.weight += o.weight;
  for (int k = 0; k < 3; ++k) {
    m.target[k] += o.target[k];
    m.source[k] += o.source[k];
  }
  for (int k = 0; k < 9; ++k)
    m.cross[k] += o.cross[k];
  m.pairs += o.pairs;
}

CVO_HOST_DEVICE inline void clear(TaylorSums& s) {
  s.b = s.c = s.d = s.e = 0.0;
}

CVO_HOST_DEVICE inline void add(TaylorSums& s, const TaylorSums& o) {
  s.b += o.b;
  s.c += o.c;
  s.d += o.d;
  s.e += o.e;
}

CVO_HOST_DEVICE inline void clear(PointSums& p) {
  p.weight = 0.0f;
  p.offset[0] = p.offset[1] = p.offset[2] = 0.0f;
  p.pairs = 0;
}

CVO_HOST_DEVICE inline void clear(CurvatureSums& c) {
  clear(c.moments);
  for (int k = 0; k < 21; ++k)
    c.hessian[k] = 0.0;
}

CVO_HOST_DEVICE inline void add(CurvatureSums& c, const CurvatureSums& o) {
  add(c.moments, o.moments);
  for (int k = 0; k < 21; ++k)
    c.hessian[k] += o.hessian[k];
}

CVO_HOST_DEVICE inline void clear(PointCurvature& p) {
  p.weight = 0.0f;
  for (int k = 0; k < 3; ++k)
    p.offset[k] = 0.0f;
  for (int k = 0; k < 6; ++k)
    p.outer[k] = p.shell[k] = 0.0f;
  p.pairs = 0;
}

CVO_HOST_DEVICE inline float floatFromBits(int bits) {
#if defined(__CUDA_ARCH__)
  return __int_as_float(bits);
#else
  return __builtin_bit_cast(float, bits);  // memcpy here would stop the loop vectoriser
#endif
}

// exp(x) for x <= 0, relative error below 3e-7, and 0-ish (2^-126) below -87. Plain arithmetic
// so that the CPU vectorises it and both backends compute the very same values.
CVO_HOST_DEVICE inline float expNonPositive(float x) {
  x = x < -87.0f ? -87.0f : x;
  // Round x / ln 2 to the nearest integer with the 1.5 * 2^23 trick (no floorf: it blocks SSE2).
  const float shifter = 12582912.0f;
  const float n = (x * 1.44269504f + shifter) - shifter;
  const float r = (x - n * 0.693145751953125f) - n * 1.428606765330187e-06f;  // |r| <= ln2/2
  float p = 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  return p * floatFromBits((static_cast<int>(n) + 127) << 23);
}

CVO_HOST_DEVICE inline float squaredDistance(const float* a, const float* b, int dim) {
  float sum = 0.0f;
  for (int k = 0; k < dim; ++k) {
    const float d = a[k] - b[k];
    sum += d * d;
  }
  return sum;
}

// The semantic factor w + (1 - w) cos(p, q) of two class-probability vectors, as the scaled
// distance -2 ln(factor) that adds to the other kernels' exponents. Hard (one-hot) labels: 0 for
// one class, -2 ln w across classes (a gate at w = 0); probabilities in between; an
// uninformative (uniform) vector matches everything, as if semantics were off.
constexpr float kSemanticGateDistance2 = 200.0f;  // exp(-100): never retained
CVO_HOST_DEVICE inline float semanticDistance2(const float* p, const float* q, int classes,
                                               float cross_weight) {
  float dot = 0.0f, pp = 0.0f, qq = 0.0f;
  for (int k = 0; k < classes; ++k) {
    dot += p[k] * q[k];
    pp += p[k] * p[k];
    qq += q[k] * q[k];
  }
  const float cosine = dot > 0.0f ? fminf(dot / sqrtf(pp * qq), 1.0f) : 0.0f;
  const float factor = cross_weight + (1.0f - cross_weight) * cosine;
  return factor > 1e-30f ? fminf(-2.0f * logf(factor), kSemanticGateDistance2)
                         : kSemanticGateDistance2;
}

// Scaled appearance distance: |c - c'|^2 / ell_c^2 plus the semantic distance (0 with no
// appearance kernel). Colour and semantic pointers may be null when that kernel is off.
CVO_HOST_DEVICE inline float appearanceDistance2(const KernelConstants& k, const float* color_x,
                                                 const float* color_z, const float* semantic_x,
                                                 const float* semantic_z) {
  float d2 = 0.0f;
  if (k.use_color) d2 += squaredDistance(color_x, color_z, kColorDim) * k.color_inv_ell2;
  if (k.semantic_classes > 0) {
    d2 += semanticDistance2(semantic_x, semantic_z, k.semantic_classes, k.semantic_cross_weight);
  }
  return d2;
}

// s^2 times the appearance factors: the part of a_ij that does not move with the pose.
CVO_HOST_DEVICE inline float appearanceWeight(const KernelConstants& k, float appearance_d2) {
  return k.max_weight * expNonPositive(-0.5f * appearance_d2);
}

// a_ij of a pair if it is retained (a_ij > sp_thres), else 0; (dx, dy, dz) = x - z. Scalar
// arguments: arrays or pointers here stop GCC from vectorising the CPU pair loop.
CVO_HOST_DEVICE inline float retainedPairWeight(float appearance, float dx, float dy, float dz,
                                                float inv_two_ell2, float sp_thres) {
  const float a = appearance * expNonPositive(-(dx * dx + dy * dy + dz * dz) * inv_two_ell2);
  return a > sp_thres ? a : 0.0f;
}

// Adds a pair's weight (0 for a pair not retained) to its source point's sums.
CVO_HOST_DEVICE inline void accumulatePair(PointSums& p, float a, float dx, float dy, float dz) {
  p.weight += a;
  p.offset[0] += a * dx;
  p.offset[1] += a * dy;
  p.offset[2] += a * dz;
  p.pairs += a > 0.0f ? 1u : 0u;
}

// Folds one source point's sums into the moments: sum a z = A z, sum a x = sum a (x - z) + A z,
// sum a x z^T = (sum a x) z^T.
CVO_HOST_DEVICE inline void accumulatePoint(MomentSums& m, const PointSums& p, const float* z) {
  const double w = p.weight;
  m.weight += w;
  for (int r = 0; r < 3; ++r) {
    const double target = static_cast<double>(p.offset[r]) + w * z[r];
    m.target[r] += target;
    m.source[r] += w * z[r];
    for (int c = 0; c < 3; ++c)
      m.cross[3 * r + c] += target * z[c];
  }
  m.pairs += p.pairs;
}

// 1 / width of the shell above sp_thres whose pairs stand for the threshold's kink: a quarter of
// sp_thres (narrower is noisier, wider blurs the kink).
CVO_HOST_DEVICE inline float inverseShellWidth(float sp_thres) {
  return 4.0f / sp_thres;
}

// A retained pair's share of the threshold's kink: a^2 / width when a lies in the shell just
// above sp_thres (below shell_top = sp_thres + width), else 0.
CVO_HOST_DEVICE inline float shellWeight(float a, float shell_top, float inv_shell_width) {
  return a > 0.0f && a < shell_top ? a * a * inv_shell_width : 0.0f;
}

// Adds a pair's weight (0 for a pair not retained) to its source point's curvature sums.
CVO_HOST_DEVICE inline void accumulateCurvaturePair(PointCurvature& p, float a, float dx, float dy,
                                                    float dz, float sp_thres,
                                                    float inv_shell_width) {
  const float o[6] = {dx * dx, dx * dy, dx * dz, dy * dy, dy * dz, dz * dz};
  p.weight += a;
  p.offset[0] += a * dx;
  p.offset[1] += a * dy;
  p.offset[2] += a * dz;
  p.pairs += a > 0.0f ? 1u : 0u;
  const float shell = shellWeight(a, sp_thres + 1.0f / inv_shell_width, inv_shell_width);
  for (int k = 0; k < 6; ++k) {
    p.outer[k] += a * o[k];
    p.shell[k] += shell * o[k];
  }
}

// Folds one source point (at y = T z) into the moments and, times `hessian_scale`, into the
// Hessian of G(exp(xi) T). With J = [-[y]x | I] (d y / d xi), A = sum a, b = sum a d,
// S = sum a d d^T over its pairs and B the shell sum (the pairs crossing the threshold, where
// (a - sp_thres)_+ kinks):
//   H = J^T (S + B) J / l^4 - A J^T J / l^2 + Q(b) / l^2,
// Q from the second-order terms of exp (1/2 w x (w x y) + 1/2 w x v):
//   Q_ww = (b y^T + y b^T) / 2 - (b . y) I, Q_wv = -[b]x / 2, Q_vv = 0.
CVO_HOST_DEVICE inline void accumulatePointCurvature(CurvatureSums& c, const PointCurvature& p,
                                                     const float* y_float, double inv_ell2,
                                                     double hessian_scale) {
  if (p.pairs == 0) return;
  accumulatePoint(c.moments, PointSums{p.weight, {p.offset[0], p.offset[1], p.offset[2]}, p.pairs},
                  y_float);
  const double y[3] = {y_float[0], y_float[1], y_float[2]};
  const double A = p.weight;
  const double b[3] = {p.offset[0], p.offset[1], p.offset[2]};
  double s6[6];
  for (int k = 0; k < 6; ++k)
    s6[k] = static_cast<double>(p.outer[k]) + static_cast<double>(p.shell[k]);
  const double S[3][3] = {{s6[0], s6[1], s6[2]}, {s6[1], s6[3], s6[4]}, {s6[2], s6[4], s6[5]}};
  // J (3 x 6): columns 0-2 are -[y]x, columns 3-5 the identity.
  const double J[3][6] = {{0.0, y[2], -y[1], 1.0, 0.0, 0.0},
                          {-y[2], 0.0, y[0], 0.0, 1.0, 0.0},
                          {y[1], -y[0], 0.0, 0.0, 0.0, 1.0}};
  double SJ[3][6];  // S J
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 6; ++k)
      SJ[r][k] = S[r][0] * J[0][k] + S[r][1] * J[1][k] + S[r][2] * J[2][k];
  }
  // [b]x, for Q_wv = -[b]x / 2.
  const double cross_b[3][3] = {{0.0, -b[2], b[1]}, {b[2], 0.0, -b[0]}, {-b[1], b[0], 0.0}};
  const double by = b[0] * y[0] + b[1] * y[1] + b[2] * y[2];
  const double inv_ell4 = inv_ell2 * inv_ell2;
  int slot = 0;
  for (int r = 0; r < 6; ++r) {
    for (int k = r; k < 6; ++k) {
      const double jsj = J[0][r] * SJ[0][k] + J[1][r] * SJ[1][k] + J[2][r] * SJ[2][k];
      const double jj = J[0][r] * J[0][k] + J[1][r] * J[1][k] + J[2][r] * J[2][k];
      double q = 0.0;
      if (k < 3) {
        q = 0.5 * (b[r] * y[k] + y[r] * b[k]) - (r == k ? by : 0.0);
      } else if (r < 3) {
        q = -0.5 * cross_b[r][k - 3];
      }
      c.hessian[slot++] += hessian_scale * (jsj * inv_ell4 - A * jj * inv_ell2 + q * inv_ell2);
    }
  }
}

// Moves a point by a row-major 3x4 float transform.
CVO_HOST_DEVICE inline void transformPoint(const float* T, const float* p, float* out) {
  for (int r = 0; r < 3; ++r) {
    out[r] = T[4 * r] * p[0] + T[4 * r + 1] * p[1] + T[4 * r + 2] * p[2] + T[4 * r + 3];
  }
}

// Derivatives of exp(t xi) z at t = 0: u_k = W^(k-1) (W z + v), W = [omega]x.
struct TaylorFrame {
  double u[4][3];
  double u1u1, u1u2, u2u2, u1u3;
};

CVO_HOST_DEVICE inline void cross3(const double* a, const double* b, double* out) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

CVO_HOST_DEVICE inline double dot3(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

CVO_HOST_DEVICE inline void makeTaylorFrame(const float* z, const double* xi, TaylorFrame& f) {
  const double zd[3] = {z[0], z[1], z[2]};
  cross3(xi, zd, f.u[0]);
  for (int k = 0; k < 3; ++k)
    f.u[0][k] += xi[3 + k];
  for (int n = 1; n < 4; ++n)
    cross3(xi, f.u[n - 1], f.u[n]);
  f.u1u1 = dot3(f.u[0], f.u[0]);
  f.u1u2 = dot3(f.u[0], f.u[1]);
  f.u2u2 = dot3(f.u[1], f.u[1]);
  f.u1u3 = dot3(f.u[0], f.u[2]);
}

// Adds a * (coefficients of exp(g(t)) - 1) for one pair, where g(t) is the change of the
// exponent -|x - exp(t xi) z|^2 / (2 ell^2), expanded to 4th order with d = x - z:
//   g = beta t + gamma t^2 + delta t^3 + eps t^4.
CVO_HOST_DEVICE inline void accumulateTaylorPair(TaylorSums& s, const TaylorFrame& f,
                                                 const float* x, const float* z, double weight,
                                                 double inv_ell2) {
  const double d[3] = {static_cast<double>(x[0]) - z[0], static_cast<double>(x[1]) - z[1],
                       static_cast<double>(x[2]) - z[2]};
  const double du1 = dot3(d, f.u[0]), du2 = dot3(d, f.u[1]);
  const double du3 = dot3(d, f.u[2]), du4 = dot3(d, f.u[3]);
  const double half = 0.5 * inv_ell2;
  const double beta = du1 * inv_ell2;
  const double gamma = -(f.u1u1 - du2) * half;
  const double delta = -(f.u1u2 - du3 / 3.0) * half;
  const double eps = -(0.25 * f.u2u2 + f.u1u3 / 3.0 - du4 / 12.0) * half;
  s.b += weight * beta;
  s.c += weight * (gamma + 0.5 * beta * beta);
  s.d += weight * (delta + beta * gamma + beta * beta * beta / 6.0);
  s.e += weight * (eps + beta * delta + 0.5 * beta * beta * gamma + 0.5 * gamma * gamma +
                   beta * beta * beta * beta / 24.0);
}

}  // namespace kernels
}  // namespace cvo
