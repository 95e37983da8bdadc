#include "lumigauss/train/adam.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "lumigauss/util/error.h"

namespace lumigauss {

AdamGroup::AdamGroup(std::string name, std::size_t size, double lr, int row_width, double eps, double beta1,
                     double beta2)
    : name_(std::move(name)),
      lr_(lr),
      eps_(eps),
      beta1_(beta1),
      beta2_(beta2),
      row_width_(row_width),
      m_(size, 0.0f),
      v_(size, 0.0f) {
    if (row_width < 1 || size % static_cast<std::size_t>(row_width) != 0)
        throw Error("Adam group '" + name_ + "': size is not a multiple of the row width");
}

void AdamGroup::step(std::span<float> params, std::span<const float> grads) {
    if (params.size() != m_.size() || grads.size() != m_.size())
        throw Error("Adam group '" + name_ + "': parameter/gradient size differs from the optimizer state");
    ++step_;
    const double t = static_cast<double>(step_);
    const double bias1 = 1.0 - std::pow(beta1_, t);
    const double bias2_sqrt = std::sqrt(1.0 - std::pow(beta2_, t));
    const auto step_size = static_cast<float>(lr_ / bias1);
    const auto bias2_sqrt_f = static_cast<float>(bias2_sqrt);
    const auto w1 = static_cast<float>(1.0 - beta1_), b2 = static_cast<float>(beta2_);
    const auto w2 = static_cast<float>(1.0 - beta2_), eps = static_cast<float>(eps_);
    // The element operations in torch's order: exp_avg.lerp_(g, 1 - b1) (= m + (1-b1)(g - m) for a weight
    // below 0.5), exp_avg_sq.mul_(b2).addcmul_(g, g, 1 - b2), denom = sqrt(v) / bias2_sqrt + eps,
    // param.addcdiv_(m, denom, -step_size).
    for (std::size_t i = 0; i < m_.size(); ++i) {
        const float g = grads[i];
        m_[i] += w1 * (g - m_[i]);
        v_[i] = v_[i] * b2 + w2 * g * g;
        const float denom = std::sqrt(v_[i]) / bias2_sqrt_f + eps;
        params[i] -= step_size * (m_[i] / denom);
    }
}

void AdamGroup::append_rows(std::size_t n) {
    const std::size_t total = m_.size() + n * static_cast<std::size_t>(row_width_);
    m_.resize(total, 0.0f);
    v_.resize(total, 0.0f);
}

void AdamGroup::keep_rows(std::span<const std::uint8_t> keep) {
    lumigauss::keep_rows(m_, row_width_, keep);
    lumigauss::keep_rows(v_, row_width_, keep);
}

void AdamGroup::duplicate_rows(std::span<const std::size_t> rows) {
    append_copies_of_rows(m_, row_width_, rows);
    append_copies_of_rows(v_, row_width_, rows);
}

void AdamGroup::reset_rows(std::span<const std::size_t> rows) {
    const auto w = static_cast<std::size_t>(row_width_);
    for (std::size_t r : rows) {
        if (r >= this->rows()) throw Error("Adam group '" + name_ + "': reset_rows index out of range");
        std::fill_n(m_.begin() + static_cast<std::ptrdiff_t>(r * w), w, 0.0f);
        std::fill_n(v_.begin() + static_cast<std::ptrdiff_t>(r * w), w, 0.0f);
    }
}

void AdamGroup::reset_moments() {
    std::fill(m_.begin(), m_.end(), 0.0f);
    std::fill(v_.begin(), v_.end(), 0.0f);
}

double ExponLrSchedule::operator()(std::int64_t step) const {
    if (step < 0 || (lr_init == 0.0 && lr_final == 0.0)) return 0.0;
    double delay_rate = 1.0;
    if (delay_steps > 0) {
        const double u = std::clamp(static_cast<double>(step) / static_cast<double>(delay_steps), 0.0, 1.0);
        delay_rate = delay_mult + (1.0 - delay_mult) * std::sin(0.5 * std::numbers::pi * u);
    }
    const double t = std::clamp(static_cast<double>(step) / static_cast<double>(max_steps), 0.0, 1.0);
    return delay_rate * std::exp(std::log(lr_init) * (1.0 - t) + std::log(lr_final) * t);
}

void AdamGroup::restore(std::int64_t step, std::vector<float> exp_avg, std::vector<float> exp_avg_sq) {
    if (exp_avg.size() != m_.size() || exp_avg_sq.size() != v_.size())
        throw Error("Adam group '" + name_ + "': saved moments have " + std::to_string(exp_avg.size()) +
                    " values, the parameters " + std::to_string(m_.size()));
    step_ = step;
    m_ = std::move(exp_avg);
    v_ = std::move(exp_avg_sq);
}

}  // namespace lumigauss
