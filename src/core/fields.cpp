#include "focal/core/fields.h"

namespace focal {

std::string_view class_name(PointClass c) {
  switch (c) {
    case PointClass::elliptic:
      return "elliptic";
    case PointClass::hyperbolic:
      return "hyperbolic";
    case PointClass::parabolic:
      return "parabolic";
    case PointClass::umbilic:
      return "umbilic";
    case PointClass::flat:
      return "flat";
    case PointClass::undefined:
      return "undefined";
  }
  return "undefined";
}

}  // namespace focal
