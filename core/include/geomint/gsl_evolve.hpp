#pragma once
// GSL's adaptive ODE stepping — a gsl_odeiv2 step, its control on y and the evolve object — as one value that
// frees what it allocates, for the baselines that drive gsl_odeiv2_evolve_apply themselves (every accepted step
// observed, no output grid imposed on the method).
#include <cstddef>

#include <gsl/gsl_odeiv2.h>

namespace geomint {

class GslEvolve {
 public:
  // `type`: e.g. gsl_odeiv2_step_rk8pd; the control keeps the local error of y below eps_abs + eps_rel |y|.
  GslEvolve(const gsl_odeiv2_step_type* type, std::size_t dim, double eps_abs, double eps_rel)
      : step_(gsl_odeiv2_step_alloc(type, dim)),
        control_(gsl_odeiv2_control_y_new(eps_abs, eps_rel)),
        evolve_(gsl_odeiv2_evolve_alloc(dim)) {}
  ~GslEvolve() {
    gsl_odeiv2_evolve_free(evolve_);
    gsl_odeiv2_control_free(control_);
    gsl_odeiv2_step_free(step_);
  }
  GslEvolve(const GslEvolve&) = delete;
  GslEvolve& operator=(const GslEvolve&) = delete;

  // One accepted step from t toward t1 (never beyond it); t, the step size h and y are updated. GSL's status.
  int apply(gsl_odeiv2_system& sys, double& t, double t1, double& h, double y[]) {
    return gsl_odeiv2_evolve_apply(evolve_, control_, step_, &sys, &t, t1, &h, y);
  }
  // Forgets the step history (after the state was changed from outside).
  void reset() {
    gsl_odeiv2_evolve_reset(evolve_);
    gsl_odeiv2_step_reset(step_);
  }

 private:
  gsl_odeiv2_step* step_;
  gsl_odeiv2_control* control_;
  gsl_odeiv2_evolve* evolve_;
};

}  // namespace geomint
