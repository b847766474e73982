# Sources of colmap_ext/controllers/ and image/ that the patch series
# compiles into COLMAP's colmap_controllers library (the mapper and the
# commands call them), and what they link. Included before COLMAP's CMake
# files are read.
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs)
set(SPHERA_COLMAP_CONTROLLER_SRCS
  ${CMAKE_CURRENT_LIST_DIR}/controllers/dual_fisheye_splitting.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/image_errors.cc
  ${CMAKE_CURRENT_LIST_DIR}/image/dual_fisheye_split.cc
  ${CMAKE_CURRENT_LIST_DIR}/image/flat_field.cc
  ${CMAKE_CURRENT_LIST_DIR}/image/image_file_structure.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/mapper_report.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/matching_status.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/model_evaluation.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/option_values.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/rig_calibration.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/rig_direction_check.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/rig_model_merge.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/sphere_bundle_adjustment.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/sphere_undistortion.cc
  ${CMAKE_CURRENT_LIST_DIR}/controllers/strecha_import.cc)
# The source of colmap_ext/scene/ that the patch series compiles into
# COLMAP's colmap_scene_types library, beside camera.cc: a camera's category.
set(SPHERA_COLMAP_SCENE_TYPES_SRCS
  ${CMAKE_CURRENT_LIST_DIR}/scene/camera_category.cc)
# Sources of colmap_ext/scene/ that the patch series compiles into COLMAP's
# colmap_scene library (the database opens through them and checks its
# cameras; the mapper, in colmap_sfm above it, checks refined intrinsics
# with them; projection.cc measures a spherical camera's reprojection error
# with one).
set(SPHERA_COLMAP_SCENE_SRCS
  ${CMAKE_CURRENT_LIST_DIR}/scene/camera_params_error.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/database_check.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/intrinsics_divergence.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/points_at_camera_center.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/rig_config.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/sphere_reprojection_error.cc
  ${CMAKE_CURRENT_LIST_DIR}/scene/unused_cameras.cc)
# Sources of colmap_ext/sfm/ that the patch series compiles into COLMAP's
# colmap_sfm library (the incremental mapper's initial pair search and its
# pairs of rig frames, the global mapper's bundle adjustments with held
# lenses).
set(SPHERA_COLMAP_SFM_SRCS
  ${CMAKE_CURRENT_LIST_DIR}/sfm/held_bundle_adjustment.cc
  ${CMAKE_CURRENT_LIST_DIR}/sfm/initial_pair_search.cc
  ${CMAKE_CURRENT_LIST_DIR}/sfm/rig_initial_pair.cc)
# What colmap_scene links for them: a rig config's lens given by its field
# of view and image circle starts from calibration/'s fit.
set(SPHERA_COLMAP_SCENE_LIBS $<BUILD_INTERFACE:sphera_calibration>)
set(SPHERA_COLMAP_CONTROLLER_LIBS
  $<BUILD_INTERFACE:sphera_calibration>
  $<BUILD_INTERFACE:sphera_estimators>
  $<BUILD_INTERFACE:opencv_core>
  $<BUILD_INTERFACE:opencv_imgproc>
  $<BUILD_INTERFACE:opencv_imgcodecs>)
