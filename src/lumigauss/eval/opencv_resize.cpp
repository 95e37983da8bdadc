#include "lumigauss/eval/opencv_resize.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "lumigauss/util/error.h"

namespace lumigauss {
namespace {

// One output sample along an axis: up to four source indices (already clamped) and their weights.
struct Taps {
    int index[4]{};
    double weight[4]{};
    int count = 0;
};

// OpenCV's source position of output sample d, split into floor and fraction.
void source_position(int d, int src, int dst, int& s, double& f) {
    const double x = (d + 0.5) * (double(src) / double(dst)) - 0.5;
    s = int(std::floor(x));
    f = x - s;
}

Taps cubic_taps(int d, int src, int dst) {
    int s = 0;
    double f = 0;
    source_position(d, src, dst, s, f);
    constexpr double a = -0.75;  // OpenCV's interpolateCubic
    Taps t;
    t.count = 4;
    t.weight[0] = ((a * (f + 1) - 5 * a) * (f + 1) + 8 * a) * (f + 1) - 4 * a;
    t.weight[1] = ((a + 2) * f - (a + 3)) * f * f + 1;
    t.weight[2] = ((a + 2) * (1 - f) - (a + 3)) * (1 - f) * (1 - f) + 1;
    t.weight[3] = 1 - t.weight[0] - t.weight[1] - t.weight[2];
    for (int k = 0; k < 4; ++k) t.index[k] = std::clamp(s - 1 + k, 0, src - 1);
    return t;
}

Taps linear_taps(int d, int src, int dst) {
    int s = 0;
    double f = 0;
    source_position(d, src, dst, s, f);
    if (s < 0) s = 0, f = 0;
    if (s >= src - 1) s = src - 1, f = 0;
    Taps t;
    t.count = 2;
    t.index[0] = s, t.index[1] = std::min(s + 1, src - 1);
    t.weight[0] = 1 - f, t.weight[1] = f;
    return t;
}

template <typename TapsOf>
Image resize_separable(const Image& in, int w, int h, TapsOf taps_of) {
    if (in.empty() || in.width <= 0 || in.height <= 0) throw Error("resize: the image is empty");
    if (w <= 0 || h <= 0)
        throw Error("resize: the new size " + std::to_string(w) + " x " + std::to_string(h) +
                    " is not positive");
    std::vector<Taps> xs(std::size_t(w), Taps{}), ys(std::size_t(h), Taps{});
    for (int x = 0; x < w; ++x) xs[std::size_t(x)] = taps_of(x, in.width, w);
    for (int y = 0; y < h; ++y) ys[std::size_t(y)] = taps_of(y, in.height, h);
    const int ch = in.channels;
    // Rows first (horizontal pass on every source row), then columns, as OpenCV does.
    std::vector<double> rows(std::size_t(in.height) * std::size_t(w) * std::size_t(ch), 0.0);
    for (int sy = 0; sy < in.height; ++sy)
        for (int x = 0; x < w; ++x) {
            const Taps& t = xs[std::size_t(x)];
            for (int c = 0; c < ch; ++c) {
                double v = 0;
                for (int k = 0; k < t.count; ++k) v += t.weight[k] * double(in.at(t.index[k], sy, c));
                rows[(std::size_t(sy) * std::size_t(w) + std::size_t(x)) * std::size_t(ch) + std::size_t(c)] =
                    v;
            }
        }
    Image out(w, h, ch);
    for (int y = 0; y < h; ++y) {
        const Taps& t = ys[std::size_t(y)];
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < ch; ++c) {
                double v = 0;
                for (int k = 0; k < t.count; ++k)
                    v += t.weight[k] *
                         rows[(std::size_t(t.index[k]) * std::size_t(w) + std::size_t(x)) * std::size_t(ch) +
                              std::size_t(c)];
                out.at(x, y, c) = float(v);
            }
    }
    return out;
}

}  // namespace

Image resize_cubic_opencv(const Image& image, int new_width, int new_height) {
    return resize_separable(image, new_width, new_height, cubic_taps);
}

Image resize_linear_opencv(const Image& image, int new_width, int new_height) {
    return resize_separable(image, new_width, new_height, linear_taps);
}

}  // namespace lumigauss
