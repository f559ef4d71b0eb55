// The hand-written baseline for the dual-chuck pipe cutter (machines/pipe_cutter.yaml), written
// as a competent engineer would for speed: Jiang et al. 2021's construction (equations (3)-(10) as
// corrected in the machine file's notes) with error and parameter indices resolved once, rigid
// poses as a 3x3 rotation and a 3-vector, each chuck's shared part evaluated once, no allocation.
//   (a) deviation: exact (every error motion an exact rotation, the orientation the exact
//       AngleAxis of the moved pipe);
//   (b) coefficients: the first-order Jacobian derived by hand. Each jaw tip is a serial chain,
//       so its derivative by an error at pose A is R_A u (translation) or (R_A u) x (tip - p_A)
//       (rotation); the concentricities, tilts and roll are linear in the tips' deviations, and
//       the working point moves by d(e03) + d(omega) x (P_W - C03) with d(omega) = (theta_x,
//       theta_y, theta_z) to first order.
// bench_eval.cpp checks (a) against weilgen::NumericChain and (b) against the generated
// Coefficients to rounding before timing.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "weilgen/machine/description.hpp"

class PipeCutterBaseline {
 public:
  static constexpr std::size_t kNumErrors = 70;
  struct Pose {
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
  };
  // Nominal poses of every error step (base frame), recorded by the nominal pass.
  struct Workspace {
    std::vector<Pose> at;
    std::array<Eigen::Matrix<double, 3, kNumErrors>, 6> tip_jacobian;
  };

  explicit PipeCutterBaseline(const weilgen::Description& d) {
    if (d.errors.size() != kNumErrors)
      throw std::invalid_argument(d.name + ": not the pipe cutter");
    const std::map<std::string, double> p = d.parameter_defaults();
    L01_ = p.at("L01");
    L23_ = p.at("L23");
    L04_ = p.at("L04");
    L45_ = p.at("L45");
    LW_ = p.at("LW");
    reach_ = p.at("jaw_reach");
    grip_feed_ = p.at("grip_feed");
    grip_main_ = p.at("grip_main");
    const auto err = [&](const std::string& name) {
      const int i = d.error_index(name);
      if (i < 0) throw std::invalid_argument("pipe cutter baseline: no error " + name);
      return i;
    };
    // Error motion carried by a body: Trans(δx, δy, δz) · Rx(εx) · Ry(εy) · Rz(εz).
    const auto motion = [&](std::vector<Step>& s, const std::string& k) {
      for (int a = 0; a < 3; ++a)
        s.push_back(step(Step::ErrorTranslation, a, err(std::string("E_") + "XYZ"[a] + k), 1));
      for (int a = 0; a < 3; ++a)
        s.push_back(step(Step::ErrorRotation, a, err(std::string("E_") + "ABC"[a] + k), 1));
    };
    // Chuck rotor: parallelism Ry(E_B0k) · Rz(E_C0k), the rotation A (deg), its error motion.
    const auto rotor = [&](std::vector<Step>& s, const std::string& k) {
      s.push_back(step(Step::ErrorRotation, 1, err("E_B0" + k), 1));
      s.push_back(step(Step::ErrorRotation, 2, err("E_C0" + k), 1));
      s.push_back(step(Step::Revolute, 0, 2, M_PI / 180));
      motion(s, k);
    };
    // Feeding chuck: carriage at L01 moving by X, its error motion, the rotor A12 = A04.
    feed_.push_back(fixed_step(L01_));
    feed_.push_back(step(Step::Prismatic, 0, 0, 1));
    motion(feed_, "X");
    rotor(feed_, "A12");
    main_.push_back(fixed_step(L04_ - L45_));
    rotor(main_, "A04");
    // A jaw along `axis` at stroke sign * q[coordinate]: tilt · T(q) · tilt^-1 · motion · reach,
    // tilt = Rz(E_C0k) · Rx(E_A0k) for a y jaw, Ry(E_B0k) · Rx(E_A0k) for a z jaw.
    const auto jaw = [&](const std::string& k, int axis, int coordinate, double sign,
                         double plane) {
      std::vector<Step> s;
      s.push_back(fixed_step(plane - reach_));
      const int t = err((axis == 1 ? "E_C0" : "E_B0") + k), a = err("E_A0" + k);
      s.push_back(step(Step::ErrorRotation, axis == 1 ? 2 : 1, t, 1));
      s.push_back(step(Step::ErrorRotation, 0, a, 1));
      s.push_back(step(Step::Prismatic, axis, coordinate, sign));
      s.push_back(step(Step::ErrorRotation, 0, a, -1));
      s.push_back(step(Step::ErrorRotation, axis == 1 ? 2 : 1, t, -1));
      motion(s, k);
      s.push_back(fixed_step(reach_));
      return s;
    };
    jaws_[0] = jaw("Y231", 1, 1, 1, L23_);
    jaws_[1] = jaw("Y232", 1, 1, -1, L23_);
    jaws_[2] = jaw("Y451", 1, 3, 1, L45_);
    jaws_[3] = jaw("Y452", 1, 3, -1, L45_);
    jaws_[4] = jaw("Z453", 2, 4, 1, L45_);
    jaws_[5] = jaw("Z454", 2, 4, -1, L45_);
    std::size_t slot = 0;
    for (auto* chain :
         {&feed_, &main_, &jaws_[0], &jaws_[1], &jaws_[2], &jaws_[3], &jaws_[4], &jaws_[5]})
      for (Step& s : *chain)
        if (s.kind == Step::ErrorTranslation || s.kind == Step::ErrorRotation) s.slot = slot++;
    num_slots_ = slot;
  }

  Workspace workspace() const {
    Workspace ws;
    ws.at.resize(num_slots_);
    return ws;
  }

  // q = X, Y231, A04 (deg), Y451, Z453 (mm, deg); errors in mm, rad. dx, dy, dz (mm) and da, db,
  // dc (rad) of the working point, exactly.
  void deviation(const double* q, const double* errors, double* out6) const {
    std::array<Eigen::Vector3d, 6> tip;
    tips(q, errors, nullptr, tip);
    finish(q, tip, out6);
  }

  // d(deviation)/d(error) at zero error, row-major [6][70].
  void coefficients(Workspace& ws, const double* q, double* coeff) const {
    std::array<Eigen::Vector3d, 6> tip;
    tips(q, nullptr, &ws, tip);
    jacobian(ws, q, tip, coeff);
  }

  void deviation_and_coefficients(Workspace& ws, const double* q, const double* errors,
                                  double* out6, double* coeff) const {
    std::array<Eigen::Vector3d, 6> tip;
    tips(q, nullptr, &ws, tip);
    jacobian(ws, q, tip, coeff);
    tips(q, errors, nullptr, tip);
    finish(q, tip, out6);
  }

 private:
  struct Step {
    enum Kind { Fixed, Prismatic, Revolute, ErrorTranslation, ErrorRotation } kind = Fixed;
    double x = 0;      // Fixed: translation along x (mm)
    int axis = 0;      // 0, 1, 2: x, y, z
    int index = 0;     // joint: coordinate in q; error: error index
    double scale = 1;  // joint: sign or deg -> rad; error: +1, or -1 for an inverse step
    std::size_t slot = 0;
  };
  static Step fixed_step(double x) {
    Step s;
    s.x = x;
    return s;
  }
  // A joint (index: coordinate in q, scale: sign or deg -> rad) or an error step (index: error,
  // scale: +1, or -1 for an inverse step) along or about axis 0, 1, 2.
  static Step step(Step::Kind kind, int axis, int index, double scale) {
    Step s;
    s.kind = kind;
    s.axis = axis;
    s.index = index;
    s.scale = scale;
    return s;
  }

  // Runs `steps` from m; errors == nullptr: nominal, recording the error steps' poses into ws.
  static void run(const std::vector<Step>& steps, const double* q, const double* errors,
                  Workspace* ws, Pose& m) {
    for (const Step& s : steps) {
      switch (s.kind) {
        case Step::Fixed:
          m.p += s.x * m.R.col(0);
          break;
        case Step::Prismatic:
          m.p += (s.scale * q[s.index]) * m.R.col(s.axis);
          break;
        case Step::Revolute:
          m.R = m.R * Eigen::AngleAxisd(s.scale * q[s.index], Eigen::Vector3d::Unit(s.axis));
          break;
        case Step::ErrorTranslation:
          if (errors) m.p += (s.scale * errors[s.index]) * m.R.col(s.axis);
          if (ws) ws->at[s.slot] = m;
          break;
        case Step::ErrorRotation:
          if (errors)
            m.R = m.R * Eigen::AngleAxisd(s.scale * errors[s.index], Eigen::Vector3d::Unit(s.axis));
          if (ws) ws->at[s.slot] = m;
          break;
      }
    }
  }

  void tips(const double* q, const double* errors, Workspace* ws,
            std::array<Eigen::Vector3d, 6>& tip) const {
    Pose feed, main;
    run(feed_, q, errors, ws, feed);
    run(main_, q, errors, ws, main);
    for (int j = 0; j < 6; ++j) {
      Pose m = j < 2 ? feed : main;
      run(jaws_[j], q, errors, ws, m);
      tip[j] = m.p;
    }
  }

  // Nominal tips, clamping directions and the chucks' clamping centres at pose q.
  struct Geometry {
    std::array<Eigen::Vector3d, 6> nominal;
    Eigen::Vector3d u1, u3;
    double c03, c05;
  };
  Geometry geometry(const double* q) const {
    Geometry g;
    const double a = q[2] * M_PI / 180, ca = std::cos(a), sa = std::sin(a);
    g.u1 = Eigen::Vector3d(0, ca, sa);   // the chuck's y turned by A
    g.u3 = Eigen::Vector3d(0, -sa, ca);  // the chuck's z turned by A
    g.c03 = L01_ + q[0] + L23_;
    g.c05 = L04_;
    const Eigen::Vector3d f(g.c03, 0, 0), m(g.c05, 0, 0);
    g.nominal = {f + q[1] * g.u1, f - q[1] * g.u1, m + q[3] * g.u1,
                 m - q[3] * g.u1, m + q[4] * g.u3, m - q[4] * g.u3};
    return g;
  }

  // The tips' deviations -> e03 (feeding chuck), e05 (main chuck, projected on the clamping
  // directions), roll03, roll05 (rad): linear, so the same code serves values and derivatives.
  template <typename V>
  static void chucks(const Geometry& g, const std::array<V, 6>& dt, V& e03, V& e05,
                     Eigen::Matrix<double, 1, V::ColsAtCompileTime>& roll03,
                     Eigen::Matrix<double, 1, V::ColsAtCompileTime>& roll05) {
    e03 = (dt[0] + dt[1]) / 2;
    e05 = g.u1 * (g.u1.transpose() * (dt[2] + dt[3]) / 2) +
          g.u3 * (g.u3.transpose() * (dt[4] + dt[5]) / 2);
    const auto roll = [&](int j, double centre) {
      const Eigen::Vector3d r = g.nominal[j] - Eigen::Vector3d(centre, 0, 0);
      return (Eigen::Vector3d::UnitX().cross(r).transpose() * dt[j] / r.squaredNorm()).eval();
    };
    roll03 = (roll(0, g.c03) + roll(1, g.c03)) / 2;
    roll05 = (roll(2, g.c05) + roll(3, g.c05) + roll(4, g.c05) + roll(5, g.c05)) / 4;
  }

  double roll_share(const Geometry& g) const {
    return grip_main_ / (grip_feed_ + (g.c05 - g.c03) + grip_main_);
  }

  void finish(const double* q, const std::array<Eigen::Vector3d, 6>& tip, double* out6) const {
    const Geometry g = geometry(q);
    std::array<Eigen::Vector3d, 6> dt;
    for (int j = 0; j < 6; ++j) dt[j] = tip[j] - g.nominal[j];
    Eigen::Vector3d e03, e05;
    Eigen::Matrix<double, 1, 1> r03, r05;
    chucks(g, dt, e03, e05, r03, r05);
    const double dist = g.c05 - g.c03;
    const double tz = (e05.y() - e03.y()) / dist, ty = -(e05.z() - e03.z()) / dist;
    const double tx = r05(0) + (r03(0) - r05(0)) * roll_share(g);
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(tz, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(ty, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(tx, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    // P'_W = C03 + e03 + R (P_W - C03): the pipe pivots about the feeding chuck's centre.
    const Eigen::Vector3d arm(L04_ + LW_ - g.c03, 0, q[4]);
    const Eigen::Vector3d dp = e03 + R * arm - arm;
    const Eigen::AngleAxisd aa(R);
    const Eigen::Vector3d w = aa.angle() * aa.axis();
    for (int i = 0; i < 3; ++i) {
      out6[i] = dp[i];
      out6[3 + i] = w[i];
    }
  }

  void jacobian(Workspace& ws, const double* q, const std::array<Eigen::Vector3d, 6>& tip,
                double* coeff) const {
    using J = Eigen::Matrix<double, 3, kNumErrors>;
    for (J& j : ws.tip_jacobian) j.setZero();
    // Every error step of a chain that leads to tip j moves it.
    const auto add = [&](const std::vector<Step>& steps, int first, int last) {
      for (const Step& s : steps) {
        if (s.kind == Step::Fixed || s.kind == Step::Prismatic || s.kind == Step::Revolute)
          continue;
        const Pose& a = ws.at[s.slot];
        const Eigen::Vector3d u = s.scale * a.R.col(s.axis);
        for (int j = first; j <= last; ++j)
          ws.tip_jacobian[j].col(s.index) +=
              s.kind == Step::ErrorTranslation ? u : u.cross(tip[j] - a.p).eval();
      }
    };
    add(feed_, 0, 1);
    add(main_, 2, 5);
    for (int j = 0; j < 6; ++j) add(jaws_[j], j, j);
    const Geometry g = geometry(q);
    J e03, e05;
    Eigen::Matrix<double, 1, kNumErrors> r03, r05;
    chucks(g, ws.tip_jacobian, e03, e05, r03, r05);
    const double dist = g.c05 - g.c03;
    J w;
    w.row(2) = (e05.row(1) - e03.row(1)) / dist;
    w.row(1) = -(e05.row(2) - e03.row(2)) / dist;
    w.row(0) = r05 + (r03 - r05) * roll_share(g);
    const Eigen::Vector3d arm(L04_ + LW_ - g.c03, 0, q[4]);
    const std::size_t n = kNumErrors;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d dp = e03.col(k) + w.col(k).cross(arm);
      for (int i = 0; i < 3; ++i) {
        coeff[i * n + k] = dp[i];
        coeff[(3 + i) * n + k] = w(i, k);
      }
    }
  }

  double L01_, L23_, L04_, L45_, LW_, reach_, grip_feed_, grip_main_;
  std::vector<Step> feed_, main_;
  std::array<std::vector<Step>, 6> jaws_;
  std::size_t num_slots_ = 0;
};
