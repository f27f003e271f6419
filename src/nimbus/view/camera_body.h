#pragma once
// The body of `nimbus view`'s POST /camera: a scene file's "camera" value, read as a scene file
// is read (scene/json_text.h: parse_json_text; scene/load.h: load_camera_json), so that the
// server holds its own input to the scene format's rules. A pure function of the bytes, for the
// fuzzer.

#include <string_view>

#include "nimbus/scene/scene_desc.h"

namespace nimbus {

// The camera the body describes. SceneError, one line starting "camera: ": not JSON, a key
// twice, nesting deeper than the scene format's limit, a number beyond a double ("camera: /fov:
// the number 1e999 is beyond a double's range ..."), or a camera a scene file would refuse
// ("camera: /camera/to: must differ from \"from\"").
CameraDesc parse_camera_body(std::string_view body);

}  // namespace nimbus
