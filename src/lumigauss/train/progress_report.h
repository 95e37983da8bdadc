#pragma once
// Watching a run while it trains: RUN/progress.html, rewritten (atomically) with every checkpoint and at the
// end. One self-contained page: plots of the training PSNR, the total loss and the surfel count over the
// iterations (inline SVG, read from log.jsonl), and the progress images (RUN/progress/ITERATION.png: photo |
// shadowed | unshadowed of a few fixed training views at that checkpoint), newest first, linked by relative
// path so the page works from the run folder on any machine.
#include <string>
#include <vector>

namespace lumigauss {

// The page for the text of log.jsonl (one JSON object per line; damaged lines and null PSNRs are skipped) and
// the progress images, given relative to the run folder in iteration order.
std::string progress_report_html(const std::string& run_name, const std::string& log_text,
                                 const std::vector<std::string>& progress_images);

}  // namespace lumigauss
