// `colmap rig_check --database_path DB [--max_angle_deg 10]`: after
// matching, before mapping, whether the rig config's lens directions agree
// with the verified image pairs inside frames (controllers/
// rig_direction_check.h). One line per lens; exit 1 naming each lens whose
// direction is off by more than max_angle_deg. The database is only read.
#pragma once

namespace colmap {

int RunRigCheck(int argc, char** argv);

}  // namespace colmap
