// SPDX-License-Identifier: MIT
// Private to viewer/: where the picture is taken from, shared by the renderer and the
// ParaView script writer so both show the same view.
#pragma once

#include <array>
#include <string>

class vtkUnstructuredGrid;

namespace bounce {

/// A perspective camera: VTK's position, focal point, view up and vertical view angle.
struct CameraPose {
    std::array<double, 3> position{};
    std::array<double, 3> focal_point{};
    std::array<double, 3> view_up{0, 1, 0};
    double view_angle = 30.0;  // vertical field of view, degrees
};

/// The camera for `spec`: "default" (cornell for the built-in box, else auto), "cornell" (the
/// classic front view of the published box), "auto", or "x,y,z:tx,ty,tz". fov (degrees) > 0
/// overrides the view angle. aspect = width / height of the picture.
///
/// auto: "up" is against the emitters' area-weighted normal (lights face down; +y when that is
/// undecided), snapped to an axis. Of the four bounding-box sides around it, the camera takes
/// the most open one (the share of 8 x 8 rays from the box's middle out through the side that
/// meet no face; ties go to the longer view, then -z, -y, -x). An open side (half or more) is
/// the Cornell set-up: the camera stands in front of it, looking in, at the distance that
/// frames the side in 39 degrees (or fov). A closed scene: it stands inside, just in front of
/// that wall, looking at the far wall, with the field of view that gives the far wall the share
/// of the picture it has in the Cornell view; unless an object blocks that view (or holds the
/// camera): 8 x 8 rays from six places before each of the four walls measure how far the view
/// reaches, and a place more than 10% more open than the wall's centre is taken instead. A scene open on all four sides
/// (no walls) is seen from the edge of the most open side, level, across 110 degrees. Flat scenes are looked at face-on
/// from their front. Throws InputError for a malformed spec or fov, the message starting with `camera_name` or
/// `fov_name` (the command line's "--camera", Python's "camera").
CameraPose choose_camera(vtkUnstructuredGrid* grid, const std::string& spec, double fov, double aspect,
                         const std::string& camera_name = "--camera", const std::string& fov_name = "--fov");

}  // namespace bounce
