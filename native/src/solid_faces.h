// Faces of closed convex solids (a box's six quads) that the own quads' tests
// (quad_lanes.h) may skip, decided once per packet or once per light:
//   - camera rays: a ray that starts outside a convex solid, behind the plane
//     of one of its faces (on the solid's side), can only reach that face
//     after entering the solid through another, nearer face, so the face is
//     never its first hit. A camera packet's origins lie within a lens
//     aperture: over a floor slab they see one face of its six.
//   - shadow rays: a segment that ends at a light outside the solid leaves the
//     solid, if it enters at all, through a face the light is in front of;
//     faces the light is behind block nothing that those do not.
// The sides are decided with a margin of 64 float steps of the solid's
// coordinates, far above the quads' own slack (8 steps), so a face is skipped
// only where it cannot be the answer; what can differ is which of two faces a
// ray exactly on a shared edge reports, or whether a ray that passes a hair
// (within that slack) outside a solid's edge grazes it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lc {

// The box a thread's camera rays have started in so far and the quads that
// may be a first hit from somewhere in it: a packet whose origins lie inside
// reuses the answer (a thin lens's packets soon fill its aperture's box), so
// most packets pay six comparisons. Faces skipped from a box are skipped from
// any box inside it.
struct OriginRegion {
    uint64_t solids_id = 0;  // whose SolidFaces the answer is (0: none yet)
    float lo[3], hi[3];
    uint64_t quads;
};

class SolidFaces {
  public:
    SolidFaces() = default;
    // n quads, corners + 12 k the four corners of quad k (in order round it,
    // xyz each, m); solid[k] the closed convex solid quad k is a face of
    // (any id; faces of one solid share it), or -1 for a lone quad. A solid
    // must be closed and convex (a box): the culls rely on it.
    SolidFaces(const float* corners, const int32_t* solid, int n);

    bool empty() const { return faces_.empty(); }  // no quad bounds a solid: nothing to skip

    // Bit k set (k < 64): quad k may be the first hit of a ray from some
    // active lane's origin (rows origin[3][16]); the others cannot be.
    // region: the thread's, grown to take these origins in.
    uint64_t first_hits_from(const float* const origin[3], const int* active, OriginRegion* region) const;

    // Bit k set: quad k may be the first hit of a ray from some point of the
    // box [lo_m, hi_m] (a camera's lens aperture, bounded once per tile).
    uint64_t first_hits_from_box(const double lo_m[3], const double hi_m[3]) const { return facing(lo_m, hi_m); }

    // Bit k set: quad k may block a segment that ends at light_m.
    uint64_t blocking_toward(const float light_m[3]) const;

    // Quad k's outward unit normal (k a face of a solid), or nullptr (a lone
    // quad, or one with no plane).
    const double* outward_of(int quad) const {
        const int f = quad < int(face_of_quad_.size()) ? face_of_quad_[size_t(quad)] : -1;
        return f < 0 ? nullptr : faces_[size_t(f)].outward;
    }

    // Bit j set for each quad j that is a face of the same solid as quad k
    // (k itself too); 0 for a lone quad.
    uint64_t solid_mates(int quad) const;

    // Faces of solids a ray may meet: each lone quad, and at most three of a
    // box's six from any point outside it (the count the own quads' limit
    // takes, quad_lanes.h's max_own_quads).
    static int faces_met(const int32_t* solid, int n);

  private:
    struct Face {
        int quad;             // its index among the quads
        int solid;            // into solids_
        double outward[3];    // unit normal, away from the solid
        double offset_m;      // outward . (a corner)
    };
    struct Bounds {
        double lo[3], hi[3];  // the solid's corners' box (m)
        double margin_m;      // the sides' margin
    };
    // All quads but the faces of solids that every point of the box [lo, hi]
    // is outside of and behind.
    uint64_t facing(const double* lo, const double* hi) const;

    std::vector<Face> faces_;
    std::vector<int> face_of_quad_;  // per quad, its index in faces_, or -1
    std::vector<Bounds> solids_;
    uint64_t id_ = 0;  // unique per construction with faces, for OriginRegion
};

}  // namespace lc
