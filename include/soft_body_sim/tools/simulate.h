// The headless simulator behind `scripts/simulate`: runs a scene file for a duration and writes node
// positions as CSV. A library function so that its contract is unit-tested; the executable only calls it.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace soft_body_sim
{
/// Usage: simulate --scene FILE [--duration S] [--integrator NAME] [--dt S] [--substeps N]
///                 [--iterations N] [--every K] [--csv FILE] [--forces FILE] [--tensions FILE] [--images DIR]
/// Runs round(duration / dt) steps from t = 0 and writes `t,body,node,x,y,z` rows (17 significant
/// digits) at t = 0, every K steps when --every is given, and after the last step; to `out` unless
/// --csv names a file. At the same times, --forces writes `t,body,anchor,fx,fy,fz,tx,ty,tz` per anchor
/// (the wrench its body exerts on it, World::anchorWrenches) and --tensions `t,body,kind,index,a,b,tension`
/// per spring and constraint (kind "spring" or "constraint", its place among its body's springs or
/// constraints, its ends' node indices in the body). --images writes each of the scene's cameras' frames
/// at its rate, from t = 0, into the directory DIR as PNG files (camera_images.h); a camera on a tf frame
/// takes none (a note on `err`). Command-line values override the scene file's. Before running, writes one
/// line "simulate: warning: ..." to `err` for each stability limit an explicit integrator may exceed
/// (see stability.h). On bad input writes one line to `err` and returns non-zero; returns 0 on success.
int runSimulate(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace soft_body_sim
