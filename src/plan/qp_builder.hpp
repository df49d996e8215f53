#pragma once
// The planner's QP assembly (internal to plan/: planner.cpp): the
// T-independent matrices of an order and the builder of the constraint rows
// and of the full and the reduced QP for a set of durations.
#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "touchdown/core/error.hpp"
#include "touchdown/plan/bezier.hpp"
#include "touchdown/plan/planner.hpp"
#include "touchdown/plan/qp.hpp"

namespace touchdown::plan::assembly {

constexpr double kPi = 3.14159265358979323846;
constexpr int kOctagon = 8;  // sides of the polygon inscribed in a rotating pad's limit circle

inline Eigen::Matrix2d rot2(double angle) {
  Eigen::Matrix2d R;
  R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  return R;
}

// The T-independent matrices of one order: derivative matrices D_j (with
// respect to τ), the jerk Gram form D₃ᵀ G D₃, and the elevations of the
// velocity (n−1 → n) and acceleration (n−2 → n) control points.
struct OrderTables {
  int n = 0;
  std::array<Eigen::MatrixXd, 3> D;
  Eigen::MatrixXd jerk;  // per unit duration: divide by T⁵
  Eigen::MatrixXd E1, E2;
  explicit OrderTables(int order) : n(order) {
    for (int j = 0; j < 3; ++j) D[static_cast<std::size_t>(j)] = derivative_matrix(n, j);
    jerk = jerk_cost_matrix(n, 1.0);
    E1 = elevation_matrix(n - 1, 1);
    E2 = elevation_matrix(n - 2, 2);
  }
};

// The constraint rows of one set of durations, sparse (each touches a few
// control points): equalities (start, goal, continuity) and inequalities
// (corridor, velocity, acceleration). Their count does not depend on the
// durations. `skip` leaves a group out (the diagnosis); for Boundary that is
// the goal's velocity and acceleration (the start is measured, the goal's
// position is the point of the plan, continuity is the curve's own).
class QpBuilder {
 public:
  QpBuilder(const KinematicState& start, const KinematicState& goal, const PadMotion& pad,
            const PlannerOptions& options, const std::vector<Polytope>& polytopes)
      : start_(start), goal_(goal), pad_(pad), o_(options), polytopes_(polytopes), t_(options.order) {}

  // A new start, goal and pad motion (the Replanner's next plan).
  void set(const KinematicState& start, const KinematicState& goal, const PadMotion& pad) {
    start_ = start;
    goal_ = goal;
    pad_ = pad;
  }

  int variables() const { return o_.segments * (o_.order + 1) * 3; }
  // ∫ ‖d³p/dt³‖² dt of a unit-duration segment is cᵀ jerk() c per axis.
  const Eigen::MatrixXd& jerk() const { return t_.jerk; }
  static int index(int order, int segment, int point, int axis) { return (segment * (order + 1) + point) * 3 + axis; }

  // The rows of the inequalities (and, with equalities = true, of the
  // equalities) at durations T.
  void collect(const std::vector<double>& T, int skip_group, bool equalities) const {
    terms_.clear();
    rows_eq_.clear();
    rows_in_.clear();
    if (equalities) collect_equalities(T, skip_group);
    if (skip_group != static_cast<int>(ConstraintGroup::Corridor)) add_corridor();
    if (skip_group != static_cast<int>(ConstraintGroup::Velocity)) add_limits(T, 1);
    if (skip_group != static_cast<int>(ConstraintGroup::Acceleration)) add_limits(T, 2);
  }

  // The whole QP in the control points (the exported form).
  void build(const std::vector<double>& T, QpProblem& qp, int skip_group = -1) const {
    const int n = o_.order, s = o_.segments, N = variables();
    collect(T, skip_group, true);
    qp.order = n;
    qp.segments = s;
    qp.P.setZero(N, N);
    qp.q.setZero(N);
    qp.constant = 0;
    for (int k = 0; k < s; ++k) {
      const double scale = 2 / std::pow(T[static_cast<std::size_t>(k)], 5);
      for (int axis = 0; axis < 3; ++axis) {
        for (int i = 0; i <= n; ++i) {
          for (int j = 0; j <= n; ++j) qp.P(index(n, k, i, axis), index(n, k, j, axis)) = scale * t_.jerk(i, j);
        }
      }
    }
    fill(rows_eq_, qp.A_eq, qp.b_eq, qp.eq_groups, N);
    fill(rows_in_, qp.A_in, qp.b_in, qp.in_groups, N);
  }

  // The same QP with the equalities eliminated (what the planner solves):
  // per axis, every control point is an affine function c = C y + c₀ of the
  // free ones y (the start fixes a segment's first three, continuity of p,
  // v, a the next segment's first three, the goal the last segment's last
  // three), so the QP has 3F variables, no equalities, and a definite
  // Hessian blockdiag(H, H, H), H = Σ_k C_kᵀ Q_k C_k.
  struct Reduced {
    int F = 0;             // free control points per axis
    Eigen::MatrixXd C;     // M × F (M control points per axis)
    Eigen::MatrixXd c0;    // M × 3
    Eigen::MatrixXd P, A;  // 3F × 3F, m × 3F
    Eigen::VectorXd q, b;  // 3F, m
    std::vector<ConstraintGroup> groups;
  };
  void reduce(const std::vector<double>& T, Reduced& r, int skip_group = -1) const {
    const int n = o_.order, s = o_.segments, M = s * (n + 1);
    const bool relax_goal = skip_group == static_cast<int>(ConstraintGroup::Boundary);
    collect(T, skip_group, false);
    r.F = 0;
    for (int k = 0; k < s; ++k) {
      for (int i = 3; i <= n; ++i) r.F += (k == s - 1 && i >= n - (relax_goal ? 0 : 2)) ? 0 : 1;
    }
    const int F = r.F;
    r.C.setZero(M, F);
    r.c0.setZero(M, 3);
    auto row_copy = [&](int dst, int src, double f) {  // row dst += f · row src (affine)
      r.C.row(dst) += f * r.C.row(src);
      r.c0.row(dst) += f * r.c0.row(src);
    };
    const double nn = n * (n - 1.0);
    int free_index = 0;
    for (int k = 0; k < s; ++k) {
      const int base = k * (n + 1);
      const double Tk = T[static_cast<std::size_t>(k)];
      if (k == 0) {
        r.c0.row(base) = start_.p.transpose();
        r.c0.row(base + 1) = (start_.p + start_.v * Tk / n).transpose();
        r.c0.row(base + 2) = (start_.a * Tk * Tk / nn + 2 * (start_.p + start_.v * Tk / n) - start_.p).transpose();
      } else {
        const int prev = base - (n + 1);
        const double f = Tk / T[static_cast<std::size_t>(k - 1)];
        row_copy(base, prev + n, 1);
        row_copy(base + 1, prev + n, 1 + f);
        row_copy(base + 1, prev + n - 1, -f);
        row_copy(base + 2, base + 1, 2);
        row_copy(base + 2, base, -1);
        row_copy(base + 2, prev + n, f * f);
        row_copy(base + 2, prev + n - 1, -2 * f * f);
        row_copy(base + 2, prev + n - 2, f * f);
      }
      const bool last = k == s - 1;
      for (int i = 3; i <= n; ++i) {
        if (last && !relax_goal && i >= n - 2) continue;
        if (last && relax_goal && i == n) continue;
        r.C(base + i, free_index++) = 1;
      }
      if (last) {
        r.c0.row(base + n) = goal_.p.transpose();
        if (!relax_goal) {
          r.c0.row(base + n - 1) = (goal_.p - goal_.v * Tk / n).transpose();
          r.c0.row(base + n - 2) = (goal_.a * Tk * Tk / nn + 2 * (goal_.p - goal_.v * Tk / n) - goal_.p).transpose();
        }
      }
    }
    // Hessian and gradient, per axis (in work space kept between calls:
    // a replan of the same size does not allocate).
    Eigen::MatrixXd& H = H_;
    Eigen::MatrixXd& g = g_;
    H.setZero(F, F);
    g.setZero(F, 3);
    for (int k = 0; k < s; ++k) {
      const double scale = 2 / std::pow(T[static_cast<std::size_t>(k)], 5);
      const auto Ck = r.C.middleRows(k * (n + 1), n + 1);
      QC_.noalias() = scale * t_.jerk * Ck;
      H.noalias() += Ck.transpose() * QC_;
      g.noalias() += QC_.transpose() * r.c0.middleRows(k * (n + 1), n + 1);
    }
    r.P.setZero(3 * F, 3 * F);
    r.q.resize(3 * F);
    for (int a = 0; a < 3; ++a) {
      r.P.block(a * F, a * F, F, F) = H;
      r.q.segment(a * F, F) = g.col(a);
    }
    // Inequalities in y.
    r.A.setZero(static_cast<Eigen::Index>(rows_in_.size()), 3 * F);
    r.b.resize(static_cast<Eigen::Index>(rows_in_.size()));
    r.groups.resize(rows_in_.size());
    for (std::size_t row = 0; row < rows_in_.size(); ++row) {
      double rhs = rows_in_[row].rhs;
      for (std::size_t t = rows_in_[row].begin; t < rows_in_[row].end; ++t) {
        const int m = terms_[t].var / 3, a = terms_[t].var % 3;
        const double c = terms_[t].coefficient;
        if (F > 0) r.A.row(static_cast<Eigen::Index>(row)).segment(a * F, F) += c * r.C.row(m);
        rhs -= c * r.c0(m, a);
      }
      r.b(static_cast<Eigen::Index>(row)) = rhs;
      r.groups[row] = rows_in_[row].group;
    }
  }

 private:
  struct Term {
    int var;
    double coefficient;
  };
  struct Row {
    ConstraintGroup group;
    double rhs;
    std::size_t begin, end;  // terms_[begin, end)
  };
  void open_row(std::vector<Row>& rows, ConstraintGroup group, double rhs) const {
    rows.push_back({group, rhs, terms_.size(), terms_.size()});
  }
  void term(std::vector<Row>& rows, int var, double coefficient) const {
    if (coefficient == 0) return;
    terms_.push_back({var, coefficient});
    rows.back().end = terms_.size();
  }

  void fill(const std::vector<Row>& rows, Eigen::MatrixXd& A, Eigen::VectorXd& b, std::vector<ConstraintGroup>& groups,
            int N) const {
    A.setZero(static_cast<Eigen::Index>(rows.size()), N);
    b.resize(static_cast<Eigen::Index>(rows.size()));
    groups.resize(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      for (std::size_t t = rows[r].begin; t < rows[r].end; ++t) {
        A(static_cast<Eigen::Index>(r), terms_[t].var) += terms_[t].coefficient;
      }
      b(static_cast<Eigen::Index>(r)) = rows[r].rhs;
      groups[r] = rows[r].group;
    }
  }

  void collect_equalities(const std::vector<double>& T, int skip_group) const {
    const int n = o_.order, s = o_.segments;
    const std::array<const Eigen::Vector3d*, 3> start_d = {&start_.p, &start_.v, &start_.a};
    const std::array<const Eigen::Vector3d*, 3> goal_d = {&goal_.p, &goal_.v, &goal_.a};
    for (int j = 0; j < 3; ++j) {
      const auto& D = t_.D[static_cast<std::size_t>(j)];
      const double f0 = 1 / std::pow(T.front(), j), f1 = 1 / std::pow(T.back(), j);
      for (int axis = 0; axis < 3; ++axis) {
        open_row(rows_eq_, ConstraintGroup::Boundary, (*start_d[static_cast<std::size_t>(j)])(axis));
        for (int i = 0; i <= n; ++i) term(rows_eq_, index(n, 0, i, axis), f0 * D(0, i));
        if (j == 0 || skip_group != static_cast<int>(ConstraintGroup::Boundary)) {
          open_row(rows_eq_, ConstraintGroup::Boundary, (*goal_d[static_cast<std::size_t>(j)])(axis));
          for (int i = 0; i <= n; ++i) term(rows_eq_, index(n, s - 1, i, axis), f1 * D(D.rows() - 1, i));
        }
      }
      for (int k = 0; k + 1 < s; ++k) {
        const double fa = 1 / std::pow(T[static_cast<std::size_t>(k)], j);
        const double fb = 1 / std::pow(T[static_cast<std::size_t>(k + 1)], j);
        for (int axis = 0; axis < 3; ++axis) {
          open_row(rows_eq_, ConstraintGroup::Boundary, 0);
          for (int i = 0; i <= n; ++i) {
            term(rows_eq_, index(n, k, i, axis), fa * D(D.rows() - 1, i));
            term(rows_eq_, index(n, k + 1, i, axis), -fb * D(0, i));
          }
        }
      }
    }
  }

  void add_corridor() const {
    const int n = o_.order;
    for (int k = 0; k < static_cast<int>(polytopes_.size()); ++k) {
      const Polytope& poly = polytopes_[static_cast<std::size_t>(k)];
      for (int i = 0; i <= n; ++i) {
        for (int f = 0; f < poly.faces(); ++f) {
          open_row(rows_in_, ConstraintGroup::Corridor, poly.b(f));
          for (int axis = 0; axis < 3; ++axis) term(rows_in_, index(n, k, i, axis), poly.A(f, axis));
        }
      }
    }
  }

  // World-frame limits of the velocity (j = 1) or acceleration (j = 2)
  // control points (planner.hpp).
  void add_limits(const std::vector<double>& T, int j) const {
    const int n = o_.order;
    const double limit = j == 1 ? o_.v_max : o_.a_max;
    const ConstraintGroup group = j == 1 ? ConstraintGroup::Velocity : ConstraintGroup::Acceleration;
    const double w = pad_.yaw_rate;
    const Eigen::Matrix2d R0 = rot2(pad_.yaw);
    const Eigen::Vector2d vb_xy = R0.transpose() * pad_.velocity.head<2>();
    for (int k = 0; k < o_.segments; ++k) {
      const double Tk = T[static_cast<std::size_t>(k)];
      const double f = 1 / std::pow(Tk, j);
      const auto& D = t_.D[static_cast<std::size_t>(j)];  // (n−j+1) × (n+1), divided by T^j below
      // z: exact in every case (the pad turns about z and does not accelerate vertically).
      const double vz = j == 1 ? pad_.velocity.z() : 0.0;
      for (int i = 0; i < D.rows(); ++i) {
        for (const double sign : {1.0, -1.0}) {
          open_row(rows_in_, group, limit - sign * vz);
          for (int m = 0; m <= n; ++m) term(rows_in_, index(n, k, m, 2), sign * f * D(i, m));
        }
      }
      if (w == 0) {
        // Translating pad: world = R0 (pad-frame quantity) + the pad's constant world velocity; exact per axis.
        const Eigen::Vector2d pad_world = j == 1 ? Eigen::Vector2d(pad_.velocity.head<2>()) : Eigen::Vector2d::Zero();
        for (int i = 0; i < D.rows(); ++i) {
          for (int axis = 0; axis < 2; ++axis) {
            for (const double sign : {1.0, -1.0}) {
              open_row(rows_in_, group, limit - sign * pad_world(axis));
              for (int m = 0; m <= n; ++m) {
                for (int c = 0; c < 2; ++c) term(rows_in_, index(n, k, m, c), sign * f * D(i, m) * R0(axis, c));
              }
            }
          }
        }
        continue;
      }
      // Rotating pad: the pad-frame vector u (velocity: v_b + v + ω e_z × p;
      // acceleration: a + 2ω e_z × v + ω e_z × (ω e_z × p) + ω e_z × v_b),
      // elevated to order n, inside the octagon inscribed in ‖u_xy‖ ≤ limit.
      // Per elevated control point i: u_i = Σ_m (Cx(i,m) c_m + Cj(i,m) J c_m)
      // + constant, J(x, y) = (−y, x).
      Eigen::MatrixXd& Hv = Hv_;  // (n+1) × (n+1); work space kept between calls
      Eigen::MatrixXd& Cx = Cx_;
      Eigen::MatrixXd& Cj = Cj_;
      Hv.noalias() = t_.E1 * t_.D[1];
      Hv /= Tk;
      Eigen::Vector2d constant;
      if (j == 1) {
        Cx = Hv;
        Cj.setIdentity(n + 1, n + 1);
        Cj *= w;
        constant = vb_xy;
      } else {
        Cx.noalias() = t_.E2 * t_.D[2];
        Cx /= Tk * Tk;
        Cx.diagonal().array() -= w * w;
        Cj = 2 * w * Hv;
        constant = w * Eigen::Vector2d(-vb_xy.y(), vb_xy.x());
      }
      const double apothem = limit * std::cos(kPi / kOctagon);
      for (int i = 0; i <= n; ++i) {
        for (int side = 0; side < kOctagon; ++side) {
          const double th = 2 * kPi * side / kOctagon;
          const Eigen::Vector2d d(std::cos(th), std::sin(th));
          // d · (x c + y J c) = x (d · c) + y (d · J c), d · J c = −d_x c_y + d_y c_x.
          open_row(rows_in_, group, apothem - d.dot(constant));
          for (int m = 0; m <= n; ++m) {
            const double cx = Cx(i, m), cj = Cj(i, m);
            term(rows_in_, index(n, k, m, 0), cx * d.x() + cj * d.y());
            term(rows_in_, index(n, k, m, 1), cx * d.y() - cj * d.x());
          }
        }
      }
    }
  }

  KinematicState start_, goal_;
  PadMotion pad_;
  PlannerOptions o_;
  const std::vector<Polytope>& polytopes_;
  OrderTables t_;
  mutable std::vector<Term> terms_;
  mutable std::vector<Row> rows_eq_, rows_in_;
  mutable Eigen::MatrixXd H_, g_, QC_, Hv_, Cx_, Cj_;  // reduce() and add_limits() work space
};

}  // namespace touchdown::plan::assembly
