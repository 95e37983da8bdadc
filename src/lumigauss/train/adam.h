#pragma once
// Adam, one state per parameter group, exactly as torch.optim.Adam (no weight decay, no amsgrad), plus the
// row operations densification needs and the 3DGS log-linear learning-rate schedule.
//
// A group is a flat float array owned by the model (positions N x 3, opacities N x 1, ...); the optimizer
// owns only the moments and the step count. Rows are `row_width` consecutive floats. Row operations mirror
// what the 3DGS/2DGS code does to the optimizer state when it edits the parameter tensors:
//   densify (clone/split)  -> append_rows(n)        new rows get zero moments, the step count is kept
//   prune                  -> keep_rows(mask)       moments of kept rows stay with their rows
//   opacity reset          -> reset_moments()       all moments zeroed, the step count is kept
// duplicate_rows(indices) (copies moments) and reset_rows(indices) are offered for variants; the faithful
// clone/split appends rows with zero moments (cat_tensors_to_optimizer), i.e. append_rows.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "lumigauss/util/row_arrays.h"

namespace lumigauss {

class AdamGroup {
  public:
    AdamGroup() = default;
    // `size` floats in rows of `row_width`; size must be a multiple of row_width. eps 1e-15 as in 2DGS/3DGS
    // and the official LumiGauss (torch's default is 1e-8).
    AdamGroup(std::string name, std::size_t size, double lr, int row_width = 1, double eps = 1e-15,
              double beta1 = 0.9, double beta2 = 0.999);

    // One torch.optim.Adam step: t += 1; m = m + (1-b1)(g - m); v = b2 v + (1-b2) g^2;
    // p -= lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps). The scalar factors are computed in double
    // (as torch does, in Python floats), the per-element update in float.
    void step(std::span<float> params, std::span<const float> grads);

    void append_rows(std::size_t n);
    // Keeps row r iff keep[r] != 0; keep has one entry per row.
    void keep_rows(std::span<const std::uint8_t> keep);
    // Appends copies of the moments of the given rows, in order.
    void duplicate_rows(std::span<const std::size_t> rows);
    void reset_rows(std::span<const std::size_t> rows);
    void reset_moments();
    // Puts back a saved state (checkpoints): step count and both moments, each of size() floats.
    void restore(std::int64_t step, std::vector<float> exp_avg, std::vector<float> exp_avg_sq);

    const std::string& name() const { return name_; }
    double lr() const { return lr_; }
    void set_lr(double lr) { lr_ = lr; }
    double eps() const { return eps_; }
    double beta1() const { return beta1_; }
    double beta2() const { return beta2_; }
    int row_width() const { return row_width_; }
    std::size_t size() const { return m_.size(); }
    std::size_t rows() const { return m_.size() / static_cast<std::size_t>(row_width_); }
    std::int64_t step_count() const { return step_; }
    const std::vector<float>& exp_avg() const { return m_; }
    const std::vector<float>& exp_avg_sq() const { return v_; }

  private:
    std::string name_;
    double lr_ = 0, eps_ = 1e-15, beta1_ = 0.9, beta2_ = 0.999;
    int row_width_ = 1;
    std::int64_t step_ = 0;
    std::vector<float> m_, v_;  // torch's exp_avg and exp_avg_sq
};

// 3DGS `get_expon_lr_func`: log-linear from lr_init (step 0) to lr_final (step >= max_steps), optionally
// damped for the first delay_steps by delay_mult + (1 - delay_mult) sin(pi/2 clamp(step / delay_steps, 0,
// 1)). Returns 0 for a negative step or when both rates are 0. Callers pass the training iteration (1-based
// in 3DGS/LumiGauss `update_learning_rate(iteration)`).
struct ExponLrSchedule {
    double lr_init = 0;
    double lr_final = 0;
    std::int64_t delay_steps = 0;
    double delay_mult = 1.0;
    std::int64_t max_steps = 1000000;

    double operator()(std::int64_t step) const;
};

}  // namespace lumigauss
