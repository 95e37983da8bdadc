#pragma once
// The thresholds of the 2DGS surfel rasterizer (hbb1/diff-surfel-rasterization, the version pinned by the
// official LumiGauss code), one named constant each so that CPU, CUDA and the tests agree.
namespace lumigauss::raster {

inline constexpr int kTileSize = 16;
inline constexpr double kNearPlane = 0.2;   // surfel centres and per-pixel intersections nearer are skipped
inline constexpr double kFarPlane = 100.0;  // only used by the distortion map's depth mapping
inline constexpr double kAlphaMax = 0.99;   // alpha clamp: keeps 1 - alpha away from 0 for the backward
inline constexpr double kAlphaMin = 1.0 / 255;     // contributions below this are skipped
inline constexpr double kTransmittanceMin = 1e-4;  // a pixel stops once T would fall below this
inline constexpr double kSigmaCutoff = 3.0;        // the filter is centred on the 3-sigma disk's box
inline constexpr double kFilterInvSquare = 2.0;  // screen low-pass: exp(-2|x-c|^2 / 2), sigma = sqrt(2)/2 px

}  // namespace lumigauss::raster
