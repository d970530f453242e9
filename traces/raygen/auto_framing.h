#pragma once
// A camera for scenes that have none. Interiors (a probe from the middle of the scene is
// mostly enclosed, like Sponza) get an eye inside at standing height looking down the longest
// horizontal axis; objects get a three-quarter view from outside that fits the bounding sphere.
#include "traces/accel/accel.h"
#include "traces/scene/scene.h"

namespace rtsim {

/// The chosen camera; `why` says which rule picked it (for the manifest).
/// aspect: width / height of the image, so an object view fills the frame.
Camera auto_frame(const Scene& scene, const Accel& accel, float aspect, std::string* why);

}  // namespace rtsim
