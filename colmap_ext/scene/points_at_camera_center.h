// A spherical camera sees every direction, so a point's depth has no sign
// there; what leaves an observation without a direction is a point at the
// camera's centre. Bundle adjustment with the angular residual can pull a
// point there (e.g. one seen only by two lenses of a rig frame, together
// with their offset), and such a point stalls every later adjustment, its
// derivatives growing as one over the distance. COLMAP's filter of
// observations with negative depth removes these observations of spherical
// cameras instead.
#pragma once

#include "colmap/scene/image.h"
#include "colmap/scene/reconstruction.h"

#include <vector>

namespace colmap {

// The distance from a spherical camera's centre under which an observed
// point counts as at the centre: 1e-3 of the median distance of the points
// the registered spherical images observe from their centres; 0 when there
// are none.
double MinDistanceFromSphericalCenter(const Reconstruction& reconstruction);

// The observations of `image` whose 3D point is nearer than `min_distance`
// to the image's projection centre, one per 3D point (a track may hold two
// observations of one image; deleting both of a two-element track would
// delete a point twice).
std::vector<point2D_t> ObservationsAtCenter(const Reconstruction& reconstruction,
                                            const Image& image,
                                            double min_distance);

}  // namespace colmap
