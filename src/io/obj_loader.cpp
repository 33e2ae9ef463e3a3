// Placeholder until the OBJ loader lands.
#include "io/obj_loader.h"

namespace lc::io {
ObjData loadObj(const std::string& path, const SourceLoc& referredFrom, const MaterialDesc&, const Limits&) {
  throw Error(referredFrom, "obj_mesh is not supported yet ('" + path + "')");
}
SceneDesc loadObjScene(const std::string& path, const Limits&, std::string*) {
  throw Error("OBJ input is not supported yet ('" + path + "')");
}
void writeRayFromObj(const std::string& objPath, const std::string&, const Limits&) {
  throw Error("obj2ray is not supported yet ('" + objPath + "')");
}
}  // namespace lc::io
