#include "lumigauss/train/progress_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

namespace lumigauss {

namespace {

struct Series {
    const char* key;
    const char* title;
    std::vector<double> x, y;
};

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

// An axis label: whole numbers past 1000 (surfel counts, iterations) without an exponent.
std::string label(double v) {
    if (std::abs(v) < 1000) return number(v);
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
}

std::string escaped(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

// One line chart: the series against the iteration, its range written at the axis ends.
std::string svg_chart(const Series& s) {
    constexpr double kWidth = 660, kHeight = 180, kLeft = 80, kRight = 10, kTop = 10, kBottom = 24;
    std::string svg = "<figure><figcaption>" + std::string(s.title) + "</figcaption>";
    if (s.x.empty()) return svg + "<p>no values yet</p></figure>\n";
    const auto [ymin_it, ymax_it] = std::minmax_element(s.y.begin(), s.y.end());
    double ymin = *ymin_it, ymax = *ymax_it;
    if (ymax - ymin < 1e-12) ymin -= 0.5, ymax += 0.5;
    const double xmin = s.x.front(), xmax = std::max(s.x.back(), xmin + 1);
    const auto px = [&](double x) { return kLeft + (x - xmin) / (xmax - xmin) * (kWidth - kLeft - kRight); };
    const auto py = [&](double y) { return kTop + (ymax - y) / (ymax - ymin) * (kHeight - kTop - kBottom); };
    std::ostringstream o;
    o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kWidth << "\" height=\"" << kHeight
      << "\" class=\"chart\" data-key=\"" << s.key << "\">";
    o << "<rect x=\"" << kLeft << "\" y=\"" << kTop << "\" width=\"" << kWidth - kLeft - kRight
      << "\" height=\"" << kHeight - kTop - kBottom << "\" fill=\"none\" stroke=\"#999\"/>";
    o << "<polyline fill=\"none\" stroke=\"#1f6feb\" stroke-width=\"1.2\" points=\"";
    for (std::size_t i = 0; i < s.x.size(); ++i)
        o << (i ? " " : "") << number(px(s.x[i])) << "," << number(py(s.y[i]));
    o << "\"/>";
    const auto text = [&](double x, double y, const std::string& t, const char* anchor) {
        o << "<text x=\"" << number(x) << "\" y=\"" << number(y) << "\" font-size=\"11\" text-anchor=\""
          << anchor << "\">" << t << "</text>";
    };
    text(kLeft - 4, kTop + 10, label(ymax), "end");
    text(kLeft - 4, kHeight - kBottom, label(ymin), "end");
    text(kLeft, kHeight - 8, label(xmin), "start");
    text(kWidth - kRight, kHeight - 8, label(xmax) + " iterations", "end");
    o << "</svg>";
    return svg + o.str() + "</figure>\n";
}

}  // namespace

std::string progress_report_html(const std::string& run_name, const std::string& log_text,
                                 const std::vector<std::string>& progress_images) {
    std::vector<Series> series = {
        {"psnr", "training PSNR (dB, the logged photo)", {}, {}},
        {"held_out_psnr",
         "held-out PSNR (dB, mean over the test photos: light fitted on the left half, "
         "right half scored)",
         {},
         {}},
        {"total", "total loss", {}, {}},
        {"surfels", "surfels", {}, {}}};
    std::istringstream lines(log_text);
    std::string line;
    double last_iteration = 0, elapsed = 0;
    while (std::getline(lines, line)) {
        const nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
        if (!j.is_object() || !j.contains("iteration") || !j["iteration"].is_number()) continue;
        const double it = j["iteration"].get<double>();
        last_iteration = it;
        if (j.contains("elapsed_s") && j["elapsed_s"].is_number()) elapsed = j["elapsed_s"].get<double>();
        for (Series& s : series)
            if (j.contains(s.key) && j[s.key].is_number() && std::isfinite(j[s.key].get<double>()))
                s.x.push_back(it), s.y.push_back(j[s.key].get<double>());
    }
    std::string html =
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>LumiGauss run " + escaped(run_name) +
        "</title>\n<style>body{font-family:sans-serif;margin:1em 2em}figure{margin:0.5em 0}"
        "figcaption{font-weight:bold}img{max-width:100%;image-rendering:pixelated}</style></head><body>\n";
    char minutes[32];
    std::snprintf(minutes, sizeof minutes, "%.1f", elapsed / 60);
    html += "<h1>" + escaped(run_name) + "</h1>\n<p>iteration " + label(last_iteration) + ", " + minutes +
            " min of training. Rewritten with every checkpoint; reload to follow.</p>\n";
    for (const Series& s : series) html += svg_chart(s);
    html += "<h2>Progress (photo | shadowed | unshadowed, newest first)</h2>\n";
    if (progress_images.empty()) html += "<p>none yet: the first comes with the first checkpoint</p>\n";
    for (auto it = progress_images.rbegin(); it != progress_images.rend(); ++it)
        html += "<figure><figcaption>" + escaped(*it) + "</figcaption><img src=\"" + escaped(*it) +
                "\"></figure>\n";
    return html + "</body></html>\n";
}

}  // namespace lumigauss
