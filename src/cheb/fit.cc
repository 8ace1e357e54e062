#include "cheval/cheb/fit.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <vector>

#include <Eigen/Cholesky>
#include <fmt/format.h>

#include "cheval/common/error.h"

namespace cheval::cheb {

Eigen::RowVectorXd ChebyshevSeries::Value(double t) const { return Clenshaw(coefficients, interval.ToUnit(t)); }

Eigen::RowVectorXd ChebyshevSeries::Derivative(double t) const {
  return Clenshaw(DerivativeCoefficients(coefficients), interval.ToUnit(t)) * interval.DerivativeScale();
}

Eigen::MatrixXd ChebyshevSeries::ValuesAtPoints() const { return CoefficientsToValues(coefficients); }

namespace {

// Samples are processed in chunks small enough for L1 (x, T_{n-1}, T_n, ω, ω·z of each sample),
// looping over n inside a chunk; sums run in kLanes independent accumulators so the compiler can
// vectorise without reassociating floating point. Only n = 0..N is iterated: with
// T_{2n} = 2T_n² - 1 and T_{2n+1} = 2T_n T_{n+1} - x, the upper moments are
// S_{2n} = 2Σω T_n² - S_0 and S_{2n+1} = 2Σω T_n T_{n+1} - S_1.
constexpr int kLanes = 8;
constexpr int kChunk = 512;  // a multiple of kLanes

// Vectors of 4 (AVX2) and 8 (AVX-512) doubles, for the kernels that spell their vectors out.
using Vector4 = double __attribute__((vector_size(4 * sizeof(double))));
using Vector8 = double __attribute__((vector_size(8 * sizeof(double))));

struct Moments {
  std::vector<double> s;         // S_n, n = 0..2N
  std::vector<double> squares;   // Σω T_n², n = 0..N
  std::vector<double> products;  // Σω T_n T_{n+1}, n = 0..N
  Eigen::MatrixXd b;             // Σω T_n z, (N + 1) x d
};

// Built three times where the compiler supports function multi-versioning: for x86-64-v4
// (AVX-512), x86-64-v3 (AVX2 + FMA) and the baseline; the loader picks the one the CPU runs. Not
// under the address or thread sanitizer: the loader runs the picking function before their
// runtimes start (ThreadSanitizer crashed there).
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__)
#define CHEVAL_MULTIVERSION __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define CHEVAL_MULTIVERSION
#endif

// Whether the CPU has AVX-512's 32 vector registers of 8 doubles; the kernels below keep more
// values in registers when it does.
bool WideVectors() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool wide = __builtin_cpu_supports("avx512f");
  return wide;
#else
  return false;
#endif
}

// Adds one chunk's contribution. Arrays have kChunk entries; wz is d x kChunk. kWeighted = false
// means every weight is 1 (w is not read and wz holds z): the same sums without the multiplies, so
// the results are bit-identical to the weighted kernel with unit weights. Padding needs ω = 0, so
// a partial chunk always goes through the weighted kernel.
//
// Two degrees per sweep: with A = T_n and B = T_{n+1} loaded once, the sums of degrees n and n + 1
// are accumulated and T_{n+2}, T_{n+3} are written back in place, which halves the loads and
// stores per sample and degree. Lane l of an accumulator takes the samples k ≡ l mod kLanes, in
// increasing k, so every sum adds the same terms in the same order however the lanes are swept.
// They are swept one Vector (kWidth lanes) at a time, so that a sweep's 6 + 2d accumulators stay
// in registers: all 8 lanes at once fit AVX-512's 32 registers; on AVX2's 16 they spilled to the
// stack at every sample (twice the time of 4 lanes at a time, `BM_FitLeastSquares`).
template <int D, bool kWeighted, typename Vector>
CHEVAL_MULTIVERSION void AccumulateChunk(const double* x, const double* w, const double* wz, int degree,
                                         Moments* moments) {
  constexpr int kWidth = static_cast<int>(sizeof(Vector) / sizeof(double));
  static_assert(kLanes % kWidth == 0);
  alignas(64) double t_a[kChunk], t_b[kChunk], two_x[kChunk];
  for (int k = 0; k < kChunk; ++k) {
    t_a[k] = 1.0;
    t_b[k] = x[k];
    two_x[k] = 2.0 * x[k];
  }
  // Unaligned-safe loads and stores of kWidth doubles (an out-parameter: a function returning a
  // vector changes the ABI between the clones).
  auto load = [](const double* p, Vector& v) { std::memcpy(&v, p, sizeof(v)); };
  auto put = [](double* p, const Vector& v) { std::memcpy(p, &v, sizeof(v)); };
  // One degree's sums, lane by lane.
  struct Sums {
    alignas(64) double s[kLanes], sq[kLanes], prod[kLanes], b[D][kLanes];
  };
  auto store = [moments](int n, const Sums& sums) {
    double s = 0, sq = 0, prod = 0;
    for (int l = 0; l < kLanes; ++l) s += sums.s[l], sq += sums.sq[l], prod += sums.prod[l];
    moments->s[n] += s;
    moments->squares[n] += sq;
    moments->products[n] += prod;
    for (int c = 0; c < D; ++c) {
      double bc = 0;
      for (int l = 0; l < kLanes; ++l) bc += sums.b[c][l];
      moments->b(n, c) += bc;
    }
  };
  const Vector zero = Vector{} + 0.0;
  int n = 0;
  for (; n + 1 <= degree; n += 2) {
    // Here t_a = T_n and t_b = T_{n+1}.
    Sums first, second;
    for (int l0 = 0; l0 < kLanes; l0 += kWidth) {
      Vector s0 = zero, sq0 = zero, prod0 = zero, s1 = zero, sq1 = zero, prod1 = zero, b0[D], b1[D];
      for (int c = 0; c < D; ++c) b0[c] = b1[c] = zero;
      for (int k = l0; k < kChunk; k += kLanes) {
        Vector tn, tn1, tx, wk = zero;
        load(t_a + k, tn), load(t_b + k, tn1), load(two_x + k, tx);
        if constexpr (kWeighted) load(w + k, wk);
        const Vector tn2 = tx * tn1 - tn;
        const Vector tn3 = tx * tn2 - tn1;
        const Vector wtn = kWeighted ? wk * tn : tn;
        const Vector wtn1 = kWeighted ? wk * tn1 : tn1;
        s0 += wtn;
        sq0 += wtn * tn;
        prod0 += wtn * tn1;
        s1 += wtn1;
        sq1 += wtn1 * tn1;
        prod1 += wtn1 * tn2;
        for (int c = 0; c < D; ++c) {
          Vector wzk;
          load(wz + c * kChunk + k, wzk);
          b0[c] += wzk * tn;
          b1[c] += wzk * tn1;
        }
        put(t_a + k, tn2);
        put(t_b + k, tn3);
      }
      put(first.s + l0, s0), put(first.sq + l0, sq0), put(first.prod + l0, prod0);
      put(second.s + l0, s1), put(second.sq + l0, sq1), put(second.prod + l0, prod1);
      for (int c = 0; c < D; ++c) put(first.b[c] + l0, b0[c]), put(second.b[c] + l0, b1[c]);
    }
    store(n, first);
    store(n + 1, second);
  }
  if (n == degree) {
    Sums last;
    for (int l0 = 0; l0 < kLanes; l0 += kWidth) {
      Vector s0 = zero, sq0 = zero, prod0 = zero, b0[D];
      for (int c = 0; c < D; ++c) b0[c] = zero;
      for (int k = l0; k < kChunk; k += kLanes) {
        Vector tn, tn1, wk = zero;
        load(t_a + k, tn), load(t_b + k, tn1);
        if constexpr (kWeighted) load(w + k, wk);
        const Vector wtn = kWeighted ? wk * tn : tn;
        s0 += wtn;
        sq0 += wtn * tn;
        prod0 += wtn * tn1;
        for (int c = 0; c < D; ++c) {
          Vector wzk;
          load(wz + c * kChunk + k, wzk);
          b0[c] += wzk * tn;
        }
      }
      put(last.s + l0, s0), put(last.sq + l0, sq0), put(last.prod + l0, prod0);
      for (int c = 0; c < D; ++c) put(last.b[c] + l0, b0[c]);
    }
    store(n, last);
  }
}

// w == nullptr: unit weights.
template <int D>
void AccumulateAll(const Eigen::VectorXd& x, const double* w, const Eigen::Ref<const Eigen::MatrixXd>& z, int degree,
                   Moments* moments) {
  alignas(64) double cx[kChunk], cw[kChunk], cwz[D * kChunk];
  const Eigen::Index m = x.size();
  const bool wide = WideVectors();
  for (Eigen::Index begin = 0; begin < m; begin += kChunk) {
    const int count = static_cast<int>(std::min<Eigen::Index>(kChunk, m - begin));
    for (int k = 0; k < kChunk; ++k) {
      const bool live = k < count;
      const double wk = live ? (w != nullptr ? w[begin + k] : 1.0) : 0.0;
      cx[k] = live ? x[begin + k] : 0.0;
      cw[k] = wk;
      for (int c = 0; c < D; ++c) cwz[c * kChunk + k] = live ? wk * z(begin + k, c) : 0.0;
    }
    const bool unit = w == nullptr && count == kChunk;
    if (unit && wide) {
      AccumulateChunk<D, false, Vector8>(cx, cw, cwz, degree, moments);
    } else if (unit) {
      AccumulateChunk<D, false, Vector4>(cx, cw, cwz, degree, moments);
    } else if (wide) {
      AccumulateChunk<D, true, Vector8>(cx, cw, cwz, degree, moments);
    } else {
      AccumulateChunk<D, true, Vector4>(cx, cw, cwz, degree, moments);
    }
  }
}

}  // namespace

NormalEquations BuildNormalEquations(const Eigen::Ref<const Eigen::VectorXd>& t,
                                     const Eigen::Ref<const Eigen::MatrixXd>& z, int top, const Interval& interval,
                                     const Eigen::VectorXd* weights) {
  const Eigen::Index m = t.size();
  const int d = static_cast<int>(z.cols());
  if (z.rows() != m) throw std::invalid_argument("BuildNormalEquations: t and z have different lengths");
  if (d < 1 || d > 4) throw std::invalid_argument("BuildNormalEquations: dimension must be 1..4");
  if (top < 0) throw std::invalid_argument("BuildNormalEquations: negative degree");
  if (weights != nullptr && weights->size() != m) throw std::invalid_argument("BuildNormalEquations: weights length");
  if (m < top + 1) {
    throw ComputeError(fmt::format("a degree-{} fit needs at least {} samples, got {}", top, top + 1, m));
  }
  return BuildNormalEquationsUnchecked(t, z, top, interval, weights);
}

NormalEquations BuildNormalEquationsUnchecked(const Eigen::Ref<const Eigen::VectorXd>& t,
                                              const Eigen::Ref<const Eigen::MatrixXd>& z, int top,
                                              const Interval& interval, const Eigen::VectorXd* weights) {
  return BuildNormalMomentsUnchecked(t, z, top, interval, weights).Equations();
}

NormalMoments BuildNormalMomentsUnchecked(const Eigen::Ref<const Eigen::VectorXd>& t,
                                          const Eigen::Ref<const Eigen::MatrixXd>& z, int top, const Interval& interval,
                                          const Eigen::VectorXd* weights) {
  const Eigen::Index m = t.size();
  const int d = static_cast<int>(z.cols());
  Eigen::VectorXd x(m);
  for (Eigen::Index i = 0; i < m; ++i) x[i] = interval.ToUnit(t[i]);
  const double* w = weights != nullptr ? weights->data() : nullptr;
  Moments moments;
  moments.s.assign(2 * top + 2, 0.0);
  moments.squares.assign(top + 1, 0.0);
  moments.products.assign(top + 1, 0.0);
  moments.b = Eigen::MatrixXd::Zero(top + 1, d);
  switch (d) {
    case 1: AccumulateAll<1>(x, w, z, top, &moments); break;
    case 2: AccumulateAll<2>(x, w, z, top, &moments); break;
    case 3: AccumulateAll<3>(x, w, z, top, &moments); break;
    default: AccumulateAll<4>(x, w, z, top, &moments); break;
  }
  NormalMoments normal;
  normal.interval = interval;
  normal.samples = m;
  normal.rhs = std::move(moments.b);
  Eigen::VectorXd& s = normal.sums;
  s.resize(2 * top + 1);
  for (int n = 0; n <= top; ++n) s[n] = moments.s[n];
  const double s0 = moments.s[0], s1 = top >= 1 ? moments.s[1] : 0.0;
  for (int n = 1; n <= top; ++n) {
    if (2 * n > top) s[2 * n] = 2.0 * moments.squares[n] - s0;
    if (2 * n + 1 > top && 2 * n + 1 <= 2 * top) s[2 * n + 1] = 2.0 * moments.products[n] - s1;
  }
  return normal;
}

Eigen::MatrixXd NormalMoments::Gram() const {
  const Eigen::Index size = rhs.rows();
  Eigen::MatrixXd gram(size, size);
  for (Eigen::Index j = 0; j < size; ++j) {  // column by column: the matrix is column-major
    for (Eigen::Index i = 0; i < size; ++i) gram(i, j) = 0.5 * (sums[i + j] + sums[std::abs(i - j)]);
  }
  return gram;
}

namespace {

// Σ a_k b_k over n values, in kLanes independent sums (vectorised without reassociating).
CHEVAL_MULTIVERSION double Dot(const double* a, const double* b, Eigen::Index n) {
  double lanes[kLanes] = {};
  Eigen::Index k = 0;
  for (; k + kLanes <= n; k += kLanes) {
    for (int r = 0; r < kLanes; ++r) lanes[r] += a[k + r] * b[k + r];
  }
  double sum = 0.0;
  for (; k < n; ++k) sum += a[k] * b[k];
  for (int r = 0; r < kLanes; ++r) sum += lanes[r];
  return sum;
}

}  // namespace

NestedCholesky::NestedCholesky(const NormalEquations& normal, int degree) {
  if (degree < 0 || degree > normal.top_degree()) {
    throw std::invalid_argument("NestedCholesky: degree outside the normal equations");
  }
  // Factorised in place (the same arithmetic as a copy's): a second matrix of degree 400 is 1.3 MB
  // of pages first touched at ~10 µs each (docs/velocity.md, "Speed").
  factor_ = normal.gram.topLeftCorner(degree + 1, degree + 1);
  const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(factor_);
  bool singular = llt.info() != Eigen::Success;
  if (!singular) {
    factor_.triangularView<Eigen::StrictlyUpper>().setZero();
    const Eigen::ArrayXd pivots = factor_.diagonal().array().square();
    singular = !(pivots.minCoeff() > 1e-13 * pivots.maxCoeff());
  }
  if (singular) {
    throw ComputeError(fmt::format(
        "the degree-{} least-squares fit is singular: {} samples do not determine the polynomial "
        "(too few distinct stamps?)",
        degree, normal.samples));
  }
}

Eigen::MatrixXd NestedCholesky::HeldOutErrors(const Eigen::Ref<const Eigen::MatrixXd>& train_rhs,
                                              const NormalEquations& held_out, const Eigen::RowVectorXd& squares,
                                              const std::vector<int>& degrees) const {
  const Eigen::Index d = train_rhs.cols();
  Eigen::MatrixXd error(static_cast<Eigen::Index>(degrees.size()), d);
  if (degrees.empty()) return error;
  const int top = *std::max_element(degrees.begin(), degrees.end());
  if (degrees.front() < 0 || top > degree() || train_rhs.rows() < top + 1 || held_out.top_degree() < top ||
      squares.size() != d || held_out.rhs.cols() != d) {
    throw std::invalid_argument("NestedCholesky::HeldOutErrors: degrees outside the factorisation or systems");
  }
  // The forward half of every solve is the leading part of one.
  const Eigen::MatrixXd y = Whiten(top, train_rhs);
  Eigen::MatrixXd c(top + 1, d);
  for (size_t g = 0; g < degrees.size(); ++g) {
    const Eigen::Index n = degrees[g] + 1;
    // Back substitution Lᵀc = y over the leading n rows: row i of Lᵀ is column i of L below the diagonal.
    for (Eigen::Index i = n - 1; i >= 0; --i) {
      const double* below = factor_.data() + i * factor_.outerStride() + i + 1;
      for (Eigen::Index k = 0; k < d; ++k) {
        c(i, k) = (y(i, k) - Dot(below, c.data() + k * c.outerStride() + i + 1, n - 1 - i)) / factor_(i, i);
      }
    }
    // Σz² − 2cᵀb + cᵀGc of the held-out samples.
    for (Eigen::Index k = 0; k < d; ++k) {
      const double* ck = c.data() + k * c.outerStride();
      double quadratic = 0.0;
      for (Eigen::Index j = 0; j < n; ++j) {
        quadratic += ck[j] * Dot(held_out.gram.data() + j * held_out.gram.outerStride(), ck, n);
      }
      error(static_cast<Eigen::Index>(g), k) =
          squares[k] - 2.0 * Dot(ck, held_out.rhs.data() + k * held_out.rhs.outerStride(), n) + quadratic;
    }
  }
  return error;
}

double NestedCholesky::Condition(int degree) const {
  const Eigen::ArrayXd pivots = factor_.diagonal().head(degree + 1).array().square();
  return pivots.maxCoeff() / pivots.minCoeff();
}

Eigen::MatrixXd NestedCholesky::Whiten(int degree, const Eigen::Ref<const Eigen::MatrixXd>& rhs) const {
  if (degree < 0 || degree > this->degree() || rhs.rows() < degree + 1) {
    throw std::invalid_argument("NestedCholesky::Whiten: degree outside the factorisation");
  }
  return factor_.topLeftCorner(degree + 1, degree + 1).triangularView<Eigen::Lower>().solve(rhs.topRows(degree + 1));
}

Eigen::MatrixXd NestedCholesky::Solve(int degree, const Eigen::Ref<const Eigen::MatrixXd>& rhs) const {
  if (degree < 0 || degree > this->degree() || rhs.rows() < degree + 1) {
    throw std::invalid_argument("NestedCholesky::Solve: degree outside the factorisation");
  }
  const auto lower = factor_.topLeftCorner(degree + 1, degree + 1).triangularView<Eigen::Lower>();
  Eigen::MatrixXd x = lower.solve(rhs.topRows(degree + 1));
  lower.transpose().solveInPlace(x);
  return x;
}

Eigen::VectorXd NestedCholesky::VarianceFactors(int degree, int first) const {
  if (first < 0 || first > degree || degree > this->degree()) {
    throw std::invalid_argument("NestedCholesky::VarianceFactors: coefficients outside the factorisation");
  }
  // G⁻¹ = L⁻ᵀL⁻¹, so (G⁻¹)_kk is the squared norm of column k of L⁻¹; for k >= first that column
  // is the inverse of the trailing block of L applied to e_k.
  const int n = degree + 1 - first;
  const Eigen::MatrixXd inverse = factor_.block(first, first, n, n)
                                      .triangularView<Eigen::Lower>()
                                      .solve(Eigen::MatrixXd::Identity(n, n));
  return inverse.colwise().squaredNorm().transpose();
}

ChebyshevSeries SolveNormalEquations(const NormalEquations& normal, int degree, double* gram_condition,
                                     Eigen::VectorXd* variance_factors) {
  const NestedCholesky cholesky(normal, degree);
  if (gram_condition != nullptr) *gram_condition = cholesky.Condition(degree);
  if (variance_factors != nullptr) *variance_factors = cholesky.VarianceFactors(degree);
  ChebyshevSeries series;
  series.interval = normal.interval;
  series.coefficients = cholesky.Solve(degree, normal.rhs);
  return series;
}

ChebyshevSeries FitLeastSquares(const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::MatrixXd>& z,
                                int degree, const Interval& interval, const Eigen::VectorXd* weights,
                                double* gram_condition, Eigen::VectorXd* variance_factors) {
  return SolveNormalEquations(BuildNormalEquations(t, z, degree, interval, weights), degree, gram_condition,
                              variance_factors);
}

namespace {

// Clenshaw's sums of one column a[0..n] at the points x[0..m): kVectors Vectors of points at a
// time, independent chains that stay in registers. One vector of chains is bound by the latency
// of its multiply-add; enough of them keep the FMA ports busy. Each point's recurrence is the same
// arithmetic whatever kVectors is.
template <typename Vector, int kVectors>
[[gnu::always_inline]] inline void ClenshawColumn(const double* a, Eigen::Index n, const double* x, Eigen::Index m,
                                                  double* out) {
  constexpr int kPoints = kVectors * static_cast<int>(sizeof(Vector) / sizeof(double));
  for (Eigen::Index begin = 0; begin < m; begin += kPoints) {
    const int count = static_cast<int>(std::min<Eigen::Index>(kPoints, m - begin));
    alignas(64) double lanes[kPoints];
    for (int p = 0; p < kPoints; ++p) lanes[p] = 2.0 * (p < count ? x[begin + p] : 0.0);
    Vector two_x[kVectors], b1[kVectors], b2[kVectors];
    std::memcpy(two_x, lanes, sizeof(two_x));
    for (int v = 0; v < kVectors; ++v) {
      b1[v] = Vector{} + 0.0;
      b2[v] = Vector{} + 0.0;
    }
    for (Eigen::Index k = n; k >= 1; --k) {
      const double ak = a[k];
#pragma GCC unroll 8
      for (int v = 0; v < kVectors; ++v) {
        const Vector b0 = two_x[v] * b1[v] - b2[v] + ak;
        b2[v] = b1[v];
        b1[v] = b0;
      }
    }
    alignas(64) double last[kPoints], before_last[kPoints];
    std::memcpy(last, b1, sizeof(last));
    std::memcpy(before_last, b2, sizeof(before_last));
    for (int p = 0; p < count; ++p) out[begin + p] = x[begin + p] * last[p] - before_last[p] + a[0];
  }
}

}  // namespace

CHEVAL_MULTIVERSION Eigen::MatrixXd EvaluateSeries(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                                                   const Eigen::Ref<const Eigen::VectorXd>& x) {
  const Eigen::Index n = coefficients.rows() - 1, m = x.size(), d = coefficients.cols();
  Eigen::MatrixXd result(m, d);
  // As many chains as the registers hold: a chain's vector takes three registers (2x, b_{k+1},
  // b_{k+2}). AVX-512 has 32 registers of 8 lanes, so 8 vectors of 8 fit; AVX2's 16 registers of
  // 4 lanes hold 4 vectors of 4 (2, 6 and 8 were slower). 8 vectors of 8 on AVX2 spilled to the
  // stack at every step: 11x the time (`BM_EvaluateSeries`).
  const bool wide = WideVectors();
  for (Eigen::Index c = 0; c < d; ++c) {
    const double* a = coefficients.col(c).data();
    if (wide) {
      ClenshawColumn<Vector8, 8>(a, n, x.data(), m, result.col(c).data());
    } else {
      ClenshawColumn<Vector4, 4>(a, n, x.data(), m, result.col(c).data());
    }
  }
  return result;
}

}  // namespace cheval::cheb
