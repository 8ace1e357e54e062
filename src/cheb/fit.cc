#include "cheval/cheb/fit.h"

#include <algorithm>
#include <array>
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

// Adds one chunk's contribution. Arrays have kChunk entries; wz is d x kChunk. kWeighted = false
// means every weight is 1 (w is not read and wz holds z): the same sums without the multiplies, so
// the results are bit-identical to the weighted kernel with unit weights. Padding needs ω = 0, so
// a partial chunk always goes through the weighted kernel.
//
// Two degrees per sweep: with A = T_n and B = T_{n+1} loaded once, the sums of degrees n and n + 1
// are accumulated and T_{n+2}, T_{n+3} are written back in place, which halves the loads and
// stores per sample and degree. Every sum still adds the same terms in the same order (lane l of
// an accumulator takes the samples k ≡ l mod kLanes, in increasing k), so nothing changes but speed.
template <int D, bool kWeighted>
CHEVAL_MULTIVERSION void AccumulateChunk(const double* x, const double* w, const double* wz, int degree,
                                         Moments* moments) {
  alignas(64) double t_a[kChunk], t_b[kChunk], two_x[kChunk];
  for (int k = 0; k < kChunk; ++k) {
    t_a[k] = 1.0;
    t_b[k] = x[k];
    two_x[k] = 2.0 * x[k];
  }
  auto store = [moments](int n, const double* acc_s, const double* acc_sq, const double* acc_prod,
                         const double (*acc_b)[kLanes]) {
    double s = 0, sq = 0, prod = 0;
    for (int l = 0; l < kLanes; ++l) s += acc_s[l], sq += acc_sq[l], prod += acc_prod[l];
    moments->s[n] += s;
    moments->squares[n] += sq;
    moments->products[n] += prod;
    for (int c = 0; c < D; ++c) {
      double bc = 0;
      for (int l = 0; l < kLanes; ++l) bc += acc_b[c][l];
      moments->b(n, c) += bc;
    }
  };
  int n = 0;
  for (; n + 1 <= degree; n += 2) {
    // Here t_a = T_n and t_b = T_{n+1}.
    double s0[kLanes] = {}, sq0[kLanes] = {}, prod0[kLanes] = {}, b0[D][kLanes] = {};
    double s1[kLanes] = {}, sq1[kLanes] = {}, prod1[kLanes] = {}, b1[D][kLanes] = {};
    for (int k = 0; k < kChunk; k += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const double tn = t_a[k + l], tn1 = t_b[k + l];
        const double tn2 = two_x[k + l] * tn1 - tn;
        const double tn3 = two_x[k + l] * tn2 - tn1;
        const double wtn = kWeighted ? w[k + l] * tn : tn;
        const double wtn1 = kWeighted ? w[k + l] * tn1 : tn1;
        s0[l] += wtn;
        sq0[l] += wtn * tn;
        prod0[l] += wtn * tn1;
        s1[l] += wtn1;
        sq1[l] += wtn1 * tn1;
        prod1[l] += wtn1 * tn2;
        for (int c = 0; c < D; ++c) {
          b0[c][l] += wz[c * kChunk + k + l] * tn;
          b1[c][l] += wz[c * kChunk + k + l] * tn1;
        }
        t_a[k + l] = tn2;
        t_b[k + l] = tn3;
      }
    }
    store(n, s0, sq0, prod0, b0);
    store(n + 1, s1, sq1, prod1, b1);
  }
  if (n == degree) {
    double s0[kLanes] = {}, sq0[kLanes] = {}, prod0[kLanes] = {}, b0[D][kLanes] = {};
    for (int k = 0; k < kChunk; k += kLanes) {
      for (int l = 0; l < kLanes; ++l) {
        const double tn = t_a[k + l], tn1 = t_b[k + l];
        const double wtn = kWeighted ? w[k + l] * tn : tn;
        s0[l] += wtn;
        sq0[l] += wtn * tn;
        prod0[l] += wtn * tn1;
        for (int c = 0; c < D; ++c) b0[c][l] += wz[c * kChunk + k + l] * tn;
      }
    }
    store(n, s0, sq0, prod0, b0);
  }
}

// w == nullptr: unit weights.
template <int D>
void AccumulateAll(const Eigen::VectorXd& x, const double* w, const Eigen::Ref<const Eigen::MatrixXd>& z, int degree,
                   Moments* moments) {
  alignas(64) double cx[kChunk], cw[kChunk], cwz[D * kChunk];
  const Eigen::Index m = x.size();
  for (Eigen::Index begin = 0; begin < m; begin += kChunk) {
    const int count = static_cast<int>(std::min<Eigen::Index>(kChunk, m - begin));
    for (int k = 0; k < kChunk; ++k) {
      const bool live = k < count;
      const double wk = live ? (w != nullptr ? w[begin + k] : 1.0) : 0.0;
      cx[k] = live ? x[begin + k] : 0.0;
      cw[k] = wk;
      for (int c = 0; c < D; ++c) cwz[c * kChunk + k] = live ? wk * z(begin + k, c) : 0.0;
    }
    if (w == nullptr && count == kChunk) {
      AccumulateChunk<D, false>(cx, cw, cwz, degree, moments);
    } else {
      AccumulateChunk<D, true>(cx, cw, cwz, degree, moments);
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

CHEVAL_MULTIVERSION Eigen::MatrixXd EvaluateSeries(const Eigen::Ref<const Eigen::MatrixXd>& coefficients,
                                                   const Eigen::Ref<const Eigen::VectorXd>& x) {
  const Eigen::Index n = coefficients.rows() - 1, m = x.size(), d = coefficients.cols();
  Eigen::MatrixXd result(m, d);
  // kPoints points at a time: independent Clenshaw chains, in kVectors vectors of kLanes that stay
  // in registers. One vector of chains is bound by the latency of its multiply-add; 8 of them keep
  // the FMA ports busy. Each point's recurrence is the same arithmetic in any case.
  using Vector = double __attribute__((vector_size(kLanes * sizeof(double))));
  constexpr int kVectors = 8, kPoints = kVectors * kLanes;
  for (Eigen::Index c = 0; c < d; ++c) {
    const double* a = coefficients.col(c).data();
    for (Eigen::Index begin = 0; begin < m; begin += kPoints) {
      const int count = static_cast<int>(std::min<Eigen::Index>(kPoints, m - begin));
      Vector two_x[kVectors], b1[kVectors], b2[kVectors];
      for (int v = 0; v < kVectors; ++v) {
        for (int l = 0; l < kLanes; ++l) {
          const int p = v * kLanes + l;
          two_x[v][l] = 2.0 * (p < count ? x[begin + p] : 0.0);
        }
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
      for (int p = 0; p < count; ++p) {
        const int v = p / kLanes, l = p % kLanes;
        result(begin + p, c) = x[begin + p] * b1[v][l] - b2[v][l] + a[0];
      }
    }
  }
  return result;
}

}  // namespace cheval::cheb
