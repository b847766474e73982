// `colmap rig_calibration --input_path MODEL [--gt_path GT]
//     [--output_path DIR]`: the calibration a reconstruction recovered for
// its rigs of lenses, readable and reusable.
//
// For every rig of MODEL with more than one sensor, per lens (camera; named by
// the folder of its images, e.g. "lens0"): model and parameters, focal
// lengths and their ratio, principal point, and the field of view (twice the
// largest angle from the optical axis of the rays of the pixels inside the
// image's inscribed circle around the principal point); per sensor: its pose
// relative to the reference lens (rotation angle and the lens centre in the
// rig). With --gt_path (a model of the same images, e.g. the renderer's
// sparse_gt with rigs.txt): per lens the difference of the projections over
// its inscribed circle (ground-truth pixel -> ray -> estimated pixel; median
// and max in pixels) and the focal ratio, per sensor the rotation error and
// the centre error, scaled to the ground truth by the least-squares
// similarity of the image centres.
//
// DIR/rig_config.json: the calibration in rig_configurator's format (lens
// offsets in the model's units, or the ground truth's with --gt_path), to
// configure new captures of the same camera; DIR/rig_calibration.json: every
// figure printed.
#pragma once

namespace colmap {

int RunRigCalibration(int argc, char** argv);

}  // namespace colmap
