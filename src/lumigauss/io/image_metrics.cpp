#include "lumigauss/io/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

void check_same_shape(const Image& x, const Image& y, const char* what) {
    if (x.width != y.width || x.height != y.height || x.channels != y.channels)
        throw Error(std::string(what) + ": images differ in size or channels (" + std::to_string(x.width) +
                    "x" + std::to_string(x.height) + "x" + std::to_string(x.channels) + " vs " +
                    std::to_string(y.width) + "x" + std::to_string(y.height) + "x" +
                    std::to_string(y.channels) + ")");
}

void check_mask(const Image& x, const Image& mask, const char* what) {
    if (mask.width != x.width || mask.height != x.height || mask.channels != 1)
        throw Error(std::string(what) + ": the mask must be one channel of the image's size");
}

std::size_t pixel_count(const Image& im) {
    return std::size_t(im.width) * std::size_t(im.height);
}

// scipy.ndimage 'reflect' (half-sample symmetric) extension of index i into [0, n).
int reflect_index(int i, int n) {
    if (n == 1) return 0;
    const int period = 2 * n;
    i %= period;
    if (i < 0) i += period;
    return i < n ? i : period - 1 - i;
}

// 1-D box mean of size `win` along rows (axis 0 = x) or columns, 'reflect' boundary, one plane.
std::vector<double> box_mean_1d(const std::vector<double>& in, int w, int h, int win, bool along_x) {
    std::vector<double> out(in.size());
    const int r = win / 2;
    const double inv = 1.0 / win;
    const int n = along_x ? w : h, lines = along_x ? h : w;
    for (int line = 0; line < lines; ++line) {
        for (int i = 0; i < n; ++i) {
            double s = 0;
            for (int k = -r; k <= r; ++k) {
                const int j = reflect_index(i + k, n);
                s += along_x ? in[std::size_t(line) * w + j] : in[std::size_t(j) * w + line];
            }
            (along_x ? out[std::size_t(line) * w + i] : out[std::size_t(i) * w + line]) = s * inv;
        }
    }
    return out;
}

// uniform_filter on a plane: the 1-D filter along each axis in turn (scipy's separable implementation).
std::vector<double> box_mean(const std::vector<double>& plane, int w, int h, int win) {
    return box_mean_1d(box_mean_1d(plane, w, h, win, false), w, h, win, true);
}

template <typename F>
double masked_mean_of(const Image& x, const Image& y, const Image& mask, F&& per_value, const char* what) {
    check_same_shape(x, y, what);
    check_mask(x, mask, what);
    double num = 0, den = 0;
    const std::size_t n = pixel_count(x);
    const std::size_t ch = std::size_t(x.channels);
    for (std::size_t p = 0; p < n; ++p) {
        const double m = mask.pixels[p];
        den += m;
        if (m == 0) continue;
        double s = 0;
        for (std::size_t c = 0; c < ch; ++c)
            s += per_value(double(x.pixels[p * ch + c]) - double(y.pixels[p * ch + c]));
        num += m * s;
    }
    return num / (double(x.channels) * den + kMaskedMeanEpsilon);
}

// The SSIM map in double, interleaved like the inputs.
std::vector<double> ssim_values(const Image& x, const Image& y, const SsimOptions& o) {
    check_same_shape(x, y, "ssim");
    if (o.win_size < 1 || o.win_size % 2 == 0) throw Error("ssim: the window size must be odd");
    if (x.width < o.win_size || x.height < o.win_size)
        throw Error("ssim: the image (" + std::to_string(x.width) + "x" + std::to_string(x.height) +
                    ") is smaller than the window (" + std::to_string(o.win_size) + ")");
    const int w = x.width, h = x.height;
    const std::size_t n = pixel_count(x), ch = std::size_t(x.channels);
    const double np = double(o.win_size) * double(o.win_size);
    const double cov_norm = o.sample_covariance ? np / (np - 1) : 1.0;
    const double c1 = (o.k1 * o.data_range) * (o.k1 * o.data_range);
    const double c2 = (o.k2 * o.data_range) * (o.k2 * o.data_range);
    std::vector<double> out(n * ch);
    std::vector<double> a(n), b(n), aa(n), bb(n), ab(n);
    for (std::size_t c = 0; c < ch; ++c) {
        for (std::size_t p = 0; p < n; ++p) {
            a[p] = x.pixels[p * ch + c], b[p] = y.pixels[p * ch + c];
            aa[p] = a[p] * a[p], bb[p] = b[p] * b[p], ab[p] = a[p] * b[p];
        }
        const auto ux = box_mean(a, w, h, o.win_size), uy = box_mean(b, w, h, o.win_size);
        const auto uxx = box_mean(aa, w, h, o.win_size), uyy = box_mean(bb, w, h, o.win_size);
        const auto uxy = box_mean(ab, w, h, o.win_size);
        for (std::size_t p = 0; p < n; ++p) {
            const double vx = cov_norm * (uxx[p] - ux[p] * ux[p]);
            const double vy = cov_norm * (uyy[p] - uy[p] * uy[p]);
            const double vxy = cov_norm * (uxy[p] - ux[p] * uy[p]);
            const double num = (2 * ux[p] * uy[p] + c1) * (2 * vxy + c2);
            const double den = (ux[p] * ux[p] + uy[p] * uy[p] + c1) * (vx + vy + c2);
            out[p * ch + c] = num / den;
        }
    }
    return out;
}

}  // namespace

double masked_mse(const Image& x, const Image& y, const Image& mask) {
    return masked_mean_of(
        x, y, mask, [](double d) { return d * d; }, "masked_mse");
}

double masked_mae(const Image& x, const Image& y, const Image& mask) {
    return masked_mean_of(
        x, y, mask, [](double d) { return std::abs(d); }, "masked_mae");
}

double psnr_from_mse(double mse) {
    return -10.0 * std::log10(mse + kPsnrMseEpsilon);
}

Image ssim_map(const Image& x, const Image& y, const SsimOptions& o) {
    const std::vector<double> v = ssim_values(x, y, o);
    Image out(x.width, x.height, x.channels);
    for (std::size_t i = 0; i < v.size(); ++i) out.pixels[i] = float(v[i]);
    return out;
}

double masked_ssim(const Image& x, const Image& y, const Image& mask, const SsimOptions& options) {
    check_mask(x, mask, "masked_ssim");
    const std::vector<double> s = ssim_values(x, y, options);
    const std::size_t n = pixel_count(x), ch = std::size_t(x.channels);
    double num = 0, den = 0;
    for (std::size_t p = 0; p < n; ++p) {
        const double m = mask.pixels[p];
        den += m;
        if (m == 0) continue;
        for (std::size_t c = 0; c < ch; ++c) num += m * s[p * ch + c];
    }
    if (den == 0) return std::numeric_limits<double>::quiet_NaN();
    return num / (double(x.channels) * den);
}

ImageMetrics image_metrics(const Image& x, const Image& y, const Image& mask, const SsimOptions& options) {
    ImageMetrics m;
    m.mse = masked_mse(x, y, mask);
    m.mae = masked_mae(x, y, mask);
    m.psnr = psnr_from_mse(m.mse);
    m.ssim = masked_ssim(x, y, mask, options);
    return m;
}

Image clamp01(const Image& image) {
    Image out = image;
    for (float& v : out.pixels) v = v > 0.0f ? std::min(v, 1.0f) : 0.0f;  // NaN fails v > 0
    return out;
}

Image erode_mask(const Image& mask, int size, int iterations) {
    if (mask.channels != 1) throw Error("erode_mask: the mask must have one channel");
    if (size < 1) throw Error("erode_mask: the kernel size must be positive");
    // OpenCV anchors an even kernel at size/2; for the odd sizes used here the window is centred.
    const int lo = -(size / 2), hi = size - 1 - size / 2;
    Image cur = mask;
    for (int it = 0; it < iterations; ++it) {
        Image rows(mask.width, mask.height, 1), out(mask.width, mask.height, 1);
        for (int y = 0; y < mask.height; ++y)
            for (int x = 0; x < mask.width; ++x) {
                float v = cur.at(x, y, 0);
                for (int k = std::max(0, x + lo); k <= std::min(mask.width - 1, x + hi); ++k)
                    v = std::min(v, cur.at(k, y, 0));
                rows.at(x, y, 0) = v;
            }
        for (int y = 0; y < mask.height; ++y)
            for (int x = 0; x < mask.width; ++x) {
                float v = rows.at(x, y, 0);
                for (int k = std::max(0, y + lo); k <= std::min(mask.height - 1, y + hi); ++k)
                    v = std::min(v, rows.at(x, k, 0));
                out.at(x, y, 0) = v;
            }
        cur = std::move(out);
    }
    return cur;
}

Image binarize_mask(const Image& mask, float threshold) {
    if (mask.channels != 1) throw Error("binarize_mask: the mask must have one channel");
    Image out(mask.width, mask.height, 1);
    for (std::size_t p = 0; p < mask.pixels.size(); ++p)
        out.pixels[p] = mask.pixels[p] >= threshold ? 1.f : 0.f;
    return out;
}

Image official_eval_mask(const Image& grey) {
    return binarize_mask(erode_mask(grey, 5, 1));
}

std::size_t mask_pixels(const Image& mask) {
    return std::size_t(
        std::count_if(mask.pixels.begin(), mask.pixels.end(), [](float v) { return v > 0.5f; }));
}

double angle_deg(Vec3d a, Vec3d b) {
    const double la = length(a), lb = length(b);
    if (!(la > 0) || !(lb > 0)) return std::numeric_limits<double>::quiet_NaN();
    return std::atan2(length(cross(a, b)), dot(a, b)) * (180.0 / 3.14159265358979323846);
}

AngularErrorStats angle_stats(std::vector<double> angles) {
    AngularErrorStats s;
    s.pixels = angles.size();
    if (angles.empty()) {
        s.mean_deg = s.median_deg = std::numeric_limits<double>::quiet_NaN();
        return s;
    }
    double sum = 0;
    for (double a : angles) sum += a;
    s.mean_deg = sum / double(angles.size());
    const std::size_t mid = angles.size() / 2;
    std::nth_element(angles.begin(), angles.begin() + std::ptrdiff_t(mid), angles.end());
    const double upper = angles[mid];
    if (angles.size() % 2 == 1) {
        s.median_deg = upper;
    } else {
        const double lower = *std::max_element(angles.begin(), angles.begin() + std::ptrdiff_t(mid));
        s.median_deg = 0.5 * (lower + upper);
    }
    return s;
}

AngularErrorStats normal_angular_error(const Image& predicted, const Image& truth, const Image& mask,
                                       double min_length, std::vector<double>* pooled) {
    check_same_shape(predicted, truth, "normal_angular_error");
    if (predicted.channels != 3) throw Error("normal_angular_error: normal maps need 3 channels");
    check_mask(predicted, mask, "normal_angular_error");
    std::vector<double> angles;
    std::size_t missing = 0;
    const std::size_t n = pixel_count(predicted);
    for (std::size_t p = 0; p < n; ++p) {
        if (!(mask.pixels[p] > 0.5f)) continue;
        const Vec3d t{truth.pixels[3 * p], truth.pixels[3 * p + 1], truth.pixels[3 * p + 2]};
        if (!(length(t) > min_length)) continue;
        const Vec3d q{predicted.pixels[3 * p], predicted.pixels[3 * p + 1], predicted.pixels[3 * p + 2]};
        if (!(length(q) > min_length)) {
            ++missing;
            angles.push_back(90.0);
            continue;
        }
        angles.push_back(angle_deg(q, t));
    }
    if (pooled) pooled->insert(pooled->end(), angles.begin(), angles.end());
    AngularErrorStats s = angle_stats(std::move(angles));
    s.missing = missing;
    return s;
}

void add_scale_terms(const Image& x, const Image& y, const Image& mask, ScaleFitTerms& terms) {
    check_same_shape(x, y, "add_scale_terms");
    check_mask(x, mask, "add_scale_terms");
    if (x.channels > 4) throw Error("add_scale_terms: at most 4 channels");
    const std::size_t n = pixel_count(x), ch = std::size_t(x.channels);
    for (std::size_t p = 0; p < n; ++p) {
        const double m = mask.pixels[p];
        if (m == 0) continue;
        for (std::size_t c = 0; c < ch; ++c) {
            const double a = x.pixels[p * ch + c], b = y.pixels[p * ch + c];
            terms.xy[c] += m * a * b;
            terms.xx[c] += m * a * a;
        }
    }
}

std::array<double, 4> scale_from_terms(const ScaleFitTerms& terms) {
    std::array<double, 4> s{};
    for (std::size_t c = 0; c < 4; ++c) s[c] = terms.xx[c] > 0 ? terms.xy[c] / terms.xx[c] : 1.0;
    return s;
}

Image scale_channels(const Image& x, const std::array<double, 4>& scale) {
    if (x.channels > 4) throw Error("scale_channels: at most 4 channels");
    Image out = x;
    const std::size_t ch = std::size_t(x.channels);
    for (std::size_t i = 0; i < out.pixels.size(); ++i) out.pixels[i] = float(out.pixels[i] * scale[i % ch]);
    return out;
}

}  // namespace lumigauss
