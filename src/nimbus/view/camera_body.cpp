#include "nimbus/view/camera_body.h"

#include <string>

#include "nimbus/scene/json_text.h"
#include "nimbus/scene/load.h"

namespace nimbus {

CameraDesc parse_camera_body(std::string_view body) {
  return load_camera_json(parse_json_text(std::string(body), "camera"), "camera");
}

}  // namespace nimbus
