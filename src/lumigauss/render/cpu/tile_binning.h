#pragma once
// Binning of surfels into 16x16 tiles: per tile, the list of surfels touching it, front to back.
#include "lumigauss/render/cpu/raster_state.h"

namespace lumigauss {

// Fills st.emission_offset, st.tile_start, st.entry_surfel and st.entry_emission from st.footprints,
// st.visible, st.tiles_x and st.tiles_y.
template <typename T>
void bin_surfels_to_tiles(RasterState<T>& st);

}  // namespace lumigauss
