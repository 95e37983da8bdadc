#pragma once
// The images of one view's contact sheet (eval/report.h), as every evaluation protocol fills them.
#include "lumigauss/io/image.h"

namespace lumigauss {

// What the contact sheet shows, at the evaluated resolution (3 channels each unless noted).
struct SheetPanels {
    Image truth, shadowed, unshadowed;  // photo and clamped renders
    Image albedo;                       // model albedo, gamma domain, scaled and clamped (empty: no gt)
    Image normal;                       // rendered normals encoded (n + 1)/2, black where nothing rendered
    Image shadow;                       // 1 channel: the paper's shadow image (relit_render.h), 1 = lit
    Image mask;                         // 1 channel: the evaluation mask
    Image gt_albedo, gt_normal;         // gt/albedo^(1/2.2) and gt/normal as stored (empty when absent)
    Image normal_error;                 // 1 channel: angle / 45 deg on the mask (empty when no gt/normal)
};

}  // namespace lumigauss
