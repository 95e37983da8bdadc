#include "lumigauss/model/visibility_transfer.h"

#include <tbb/combinable.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <numbers>

#include "lumigauss/math/quaternion.h"
#include "lumigauss/model/surfel_occlusion.h"
#include "lumigauss/shading/irradiance.h"
#include "lumigauss/shading/sh.h"
#include "lumigauss/util/rng.h"

namespace lumigauss {

namespace {

// The stream of each surfel side's jitter (util/rng.h): deterministic and free of the thread order.
constexpr std::uint64_t kDirectionJitter = 0x7669736a6974ULL;  // "visjit"

struct SideTransfer {
    double coeffs[kShCount];
    double visibility;  // cosine-weighted mean of V
};

SideTransfer side_transfer(const SurfelOcclusion& occlusion, SurfelOcclusion::RayScratch& scratch,
                           std::size_t surfel, Vec3d centre, const Mat3<double>& frame, double side,
                           const VisibilityTransferOptions& options) {
    const Vec3d n = frame.col(2) * side, tu = frame.col(0), tv = frame.col(1) * side;
    SideTransfer out{};
    cosine_lobe_sh(n, out.coeffs);
    const int rows = options.direction_rows;
    const int count = rows * rows;
    const double weight = std::numbers::pi / count;
    double lit = 0.0;
    Rng jitter(hash_keys(options.seed, kDirectionJitter, surfel, side > 0 ? 1 : 0));
    for (int k = 0; k < count; ++k) {
        const double u1 = ((k / rows) + jitter.uniform()) / rows;
        const double u2 = ((k % rows) + jitter.uniform()) / rows;
        const double r = std::sqrt(u1), phi = 2.0 * std::numbers::pi * u2;
        const Vec3d dir = tu * (r * std::cos(phi)) + tv * (r * std::sin(phi)) + n * std::sqrt(1.0 - u1);
        const double v = occlusion.transmittance(
            {centre, dir, options.start_distance, surfel, n, options.layer_thickness}, scratch);
        const double blocked = (1.0 - v) * (1.0 - options.bounce);
        lit += v;
        if (blocked <= 0.0) continue;
        double basis[kShCount];
        sh_basis(dir, basis);
        for (int j = 0; j < kShCount; ++j) out.coeffs[j] -= weight * blocked * basis[j];
    }
    out.visibility = lit / count;
    return out;
}

}  // namespace

VisibilityTransferReport bake_visibility_transfer(SurfelModel& model,
                                                  const VisibilityTransferOptions& options) {
    const SurfelOcclusion occlusion(model);
    tbb::enumerable_thread_specific<SurfelOcclusion::RayScratch> scratches(
        [&] { return occlusion.scratch(); });
    tbb::combinable<double> visibility_sum([] { return 0.0; }), shadowed([] { return 0.0; });
    auto& xyz = model.param(ModelParam::Xyz);
    auto& positive = model.param(ModelParam::TransferPositive);
    auto& negative = model.param(ModelParam::TransferNegative);
    tbb::parallel_for(std::size_t(0), model.size(), [&](std::size_t i) {
        auto& scratch = scratches.local();
        const Vec3d centre{xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
        const Mat3<float> r = rotation_from_unit_quaternion(model.unit_quaternion(i));
        const Mat3<double> frame = Mat3<double>::from_columns(
            r.col(0).cast<double>(), r.col(1).cast<double>(), r.col(2).cast<double>());
        for (const double side : {1.0, -1.0}) {
            const SideTransfer t = side_transfer(occlusion, scratch, i, centre, frame, side, options);
            float* stored = (side > 0 ? positive.data() : negative.data()) + i * kTransferStored;
            for (int j = 0; j < kShCount; ++j)
                for (int c = 0; c < 3; ++c) stored[j * 3 + c] = float(t.coeffs[j]);
            visibility_sum.local() += t.visibility;
            if (t.visibility < 0.5) shadowed.local() += 1.0;
        }
    });
    VisibilityTransferReport report;
    const double sides = 2.0 * double(model.size());
    if (sides > 0) {
        report.mean_visibility = visibility_sum.combine(std::plus<>()) / sides;
        report.shadowed_fraction = shadowed.combine(std::plus<>()) / sides;
    }
    return report;
}

}  // namespace lumigauss
