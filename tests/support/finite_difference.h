#pragma once
// Finite differences of a scalar function with respect to one float parameter held in memory.
namespace lumigauss::testing {

// Central difference of f() w.r.t. the float x, divided by the step actually taken in float (x +- h rounds
// to float), so small steps stay accurate when f computes in double from float parameters. x is restored.
template <typename F>
double central_difference(float& x, double h, F&& f) {
    const float x0 = x;
    const float hi = float(double(x0) + h), lo = float(double(x0) - h);
    x = hi;
    const double f_hi = f();
    x = lo;
    const double f_lo = f();
    x = x0;
    return (f_hi - f_lo) / (double(hi) - double(lo));
}

}  // namespace lumigauss::testing
