// The procedural landmarks. World frame: right-handed, +Z up, metres, ground at z = 0, the main entrance
// facing -Y (as in data/plaza). Every scene has what makes relighting hard: columns and an overhanging roof
// that cast long shadows, steps, a recessed doorway, a tower or obelisk that shades its surroundings.
#include <numbers>

#include "lumigauss/synth/world.h"
#include "lumigauss/util/error.h"

namespace lumigauss::synth {

namespace {

constexpr double kGroundHalfSize = 300.0;
constexpr double kPi = std::numbers::pi;

void add_box(World& w, Vec3d lo, Vec3d hi, int m) {
    w.prims.push_back(make_box(lo, hi, m));
}

// A wall slab spanning x0..x1 and y0..y1 from z0 to z1, with a doorway (x in -half_door..half_door, up to
// z = door_top) cut out: the opening becomes a recess whose back is whatever stands behind the slab.
void add_wall_with_doorway(World& w, double x0, double x1, double y0, double y1, double z0, double z1,
                           double half_door, double door_top, int m) {
    add_box(w, {x0, y0, z0}, {-half_door, y1, z1}, m);
    add_box(w, {half_door, y0, z0}, {x1, y1, z1}, m);
    add_box(w, {-half_door, y0, door_top}, {half_door, y1, z1}, m);
}

// A civic hall: stepped portico with six columns under an overhanging roof, a recessed door, pilasters,
// a cornice, a domed tower at the back, and a fountain on the square in front.
Landmark plaza() {
    Landmark l;
    l.name = "plaza";
    l.description =
        "civic hall with a columned portico under an overhanging roof, steps, a recessed door, "
        "pilasters, a domed tower and a fountain";
    World& w = l.world;
    const double column_r = 0.6, flute = 2 * kPi * column_r / 12;  // 12 flutes: no seam at the atan2 cut
    w.materials = {
        tiles({0.42, 0.40, 0.37}, {0.22, 0.21, 0.20}, 1.5, 0.25),        // 0 paving
        bricks({0.62, 0.36, 0.25}, {0.80, 0.77, 0.70}, 1.6, 0.8, 0.15),  // 1 hall walls
        stripes({0.86, 0.83, 0.76}, {0.70, 0.67, 0.60}, flute),          // 2 fluted columns
        noise({0.55, 0.52, 0.47}, {0.38, 0.35, 0.31}, 1.5),              // 3 roof, pediment
        tiles({0.72, 0.70, 0.66}, {0.50, 0.48, 0.45}, 1.0, 0.10),        // 4 steps, basin
        bricks({0.78, 0.68, 0.50}, {0.60, 0.53, 0.40}, 1.2, 0.6, 0.12),  // 5 tower
        noise({0.25, 0.48, 0.42}, {0.14, 0.30, 0.26}, 1.0),              // 6 copper dome
        solid({0.28, 0.18, 0.12}),                                       // 7 door
        solid({0.82, 0.79, 0.72}),                                       // 8 pilasters, cornices
    };
    w.prims.push_back(make_ground(kGroundHalfSize, 0));
    add_box(w, {-10, 1.5, 0}, {10, 20, 12}, 1);  // hall body; its front face is the back of the door recess
    add_wall_with_doorway(w, -10, 10, 0, 1.5, 0, 12, 2, 6, 1);
    add_box(w, {-1.6, 1.45, 1.2}, {1.6, 1.5, 5.6}, 7);  // door panel at the back of the recess
    add_box(w, {-2, 0, 0}, {2, 1.5, 1.2}, 4);           // threshold inside the recess
    add_box(w, {-9, -8, 0}, {9, 0, 0.4}, 4);            // three steps up to the portico
    add_box(w, {-8.6, -7.4, 0.4}, {8.6, 0, 0.8}, 4);
    add_box(w, {-8.2, -6.8, 0.8}, {8.2, 0, 1.2}, 4);
    for (double x : {-7.5, -4.5, -1.5, 1.5, 4.5, 7.5})
        w.prims.push_back(make_cylinder(x, -5.6, column_r, 1.2, 9, 2));
    add_box(w, {-10.5, -7.2, 9}, {10.5, 0, 10.2}, 3);      // overhanging portico roof
    add_box(w, {-8.5, -6.8, 10.2}, {8.5, 0, 11.6}, 3);     // pediment block
    add_box(w, {-10.4, -0.4, 12}, {10.4, 20.4, 12.6}, 8);  // cornice
    for (double y : {4.0, 8.5, 13.0, 17.5}) {
        add_box(w, {10, y - 0.5, 0}, {10.5, y + 0.5, 12}, 8);  // pilasters on both side walls
        add_box(w, {-10.5, y - 0.5, 0}, {-10, y + 0.5, 12}, 8);
    }
    add_box(w, {-3, 13, 12.6}, {3, 19, 24}, 5);                 // tower
    add_box(w, {-3.5, 12.5, 24}, {3.5, 19.5, 24.6}, 8);         // belfry cornice
    w.prims.push_back(make_cylinder(0, 16, 2.6, 24.6, 27, 5));  // drum
    w.prims.push_back(make_sphere({0, 16, 27}, 2.6, 6));        // dome (lower half inside the drum)
    w.prims.push_back(make_cylinder(0, 16, 0.4, 29.4, 31, 8));  // lantern
    w.prims.push_back(make_cylinder(0, -16, 3, 0, 0.8, 4));     // fountain basin
    w.prims.push_back(make_cylinder(0, -16, 0.4, 0.8, 3, 8));   // fountain pillar
    w.prims.push_back(make_sphere({0, -16, 3.4}, 0.6, 6));
    l.bbox_lo = {-10.5, -19, 0}, l.bbox_hi = {10.5, 20.4, 31};
    return l;
}

// A peripteral temple: three-step stylobate, twenty fluted columns round a cella with a recessed door,
// an overhanging entablature and roof; an obelisk with a bronze ball, an altar and a low wall in front.
Landmark temple() {
    Landmark l;
    l.name = "temple";
    l.description =
        "peripteral temple: stepped stylobate, 20 columns, cella with a recessed door, overhanging "
        "entablature and roof, an obelisk, an altar and a low wall";
    World& w = l.world;
    const double column_r = 0.55, flute = 2 * kPi * column_r / 16;
    w.materials = {
        noise({0.33, 0.38, 0.22}, {0.46, 0.42, 0.31}, 2.5),               // 0 grass and gravel
        tiles({0.80, 0.78, 0.72}, {0.60, 0.58, 0.54}, 1.0, 0.08),         // 1 stylobate, plinths
        stripes({0.90, 0.88, 0.84}, {0.76, 0.74, 0.70}, flute),           // 2 marble columns
        bricks({0.84, 0.74, 0.58}, {0.66, 0.60, 0.50}, 1.5, 0.75, 0.12),  // 3 cella ashlar
        noise({0.88, 0.86, 0.80}, {0.72, 0.70, 0.66}, 1.2),               // 4 entablature
        stripes({0.62, 0.24, 0.16}, {0.50, 0.18, 0.12}, 0.6),             // 5 tiled roof
        solid({0.20, 0.14, 0.10}),                                        // 6 door
        noise({0.55, 0.55, 0.58}, {0.38, 0.38, 0.42}, 0.8),               // 7 granite obelisk
        solid({0.55, 0.40, 0.20}),                                        // 8 bronze
        bricks({0.55, 0.52, 0.48}, {0.35, 0.34, 0.32}, 1.0, 0.5, 0.15),   // 9 low wall
    };
    w.prims.push_back(make_ground(kGroundHalfSize, 0));
    add_box(w, {-8.4, -12.4, 0}, {8.4, 12.4, 0.5}, 1);
    add_box(w, {-7.9, -11.9, 0.5}, {7.9, 11.9, 1.0}, 1);
    add_box(w, {-7.4, -11.4, 1.0}, {7.4, 11.4, 1.5}, 1);
    add_box(w, {-4.5, -4.5, 1.5}, {4.5, 9, 8.6}, 3);  // cella
    add_wall_with_doorway(w, -4.5, 4.5, -6, -4.5, 1.5, 8.6, 1.5, 6, 3);
    add_box(w, {-1.2, -4.55, 1.5}, {1.2, -4.5, 5.6}, 6);
    for (double x : {-6.2, -3.72, -1.24, 1.24, 3.72, 6.2}) {
        w.prims.push_back(make_cylinder(x, -10.2, column_r, 1.5, 8.6, 2));
        w.prims.push_back(make_cylinder(x, 10.2, column_r, 1.5, 8.6, 2));
    }
    for (double y : {-6.12, -2.04, 2.04, 6.12}) {
        w.prims.push_back(make_cylinder(-6.2, y, column_r, 1.5, 8.6, 2));
        w.prims.push_back(make_cylinder(6.2, y, column_r, 1.5, 8.6, 2));
    }
    add_box(w, {-7.2, -11.2, 8.6}, {7.2, 11.2, 9.8}, 4);  // entablature, overhanging the columns
    add_box(w, {-6.6, -10.6, 9.8}, {6.6, 10.6, 10.6}, 5);
    add_box(w, {-3.6, -10.2, 10.6}, {3.6, 10.2, 11.3}, 5);
    add_box(w, {11, -10, 0}, {14, -7, 1.2}, 1);  // obelisk plinth, shaft, ball
    add_box(w, {11.8, -9.2, 1.2}, {13.2, -7.8, 12}, 7);
    w.prims.push_back(make_sphere({12.5, -8.5, 12.6}, 0.65, 8));
    add_box(w, {-1.5, -17, 0}, {1.5, -15, 1.0}, 1);  // altar with a bronze bowl
    w.prims.push_back(make_cylinder(0, -16, 0.5, 1.0, 1.6, 8));
    add_box(w, {-14, -17, 0}, {-7, -16.4, 1.1}, 9);  // low wall
    l.bbox_lo = {-14, -17, 0}, l.bbox_hi = {14, 12.4, 13.25};
    return l;
}

}  // namespace

std::vector<std::string> landmark_names() {
    return {"plaza", "temple"};
}

Landmark build_landmark(const std::string& name) {
    if (name == "plaza") return plaza();
    if (name == "temple") return temple();
    throw Error("synth: unknown scene '" + name + "' (choose plaza or temple)");
}

}  // namespace lumigauss::synth
