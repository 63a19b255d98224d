// The core's rows of the settings table (settings_table.hpp): every CvoParams member with its
// name, group, range and meaning. Defaults are CvoParams' initialisers.
#pragma once

#include "cvo_odometry/core/cvo_params.hpp"
#include "cvo_odometry/core/settings_table.hpp"

namespace cvo {

template <class V>
void visitSettings(CvoParams& p, V&& v) {
  // Kernels
  v(SettingInfo{"ell_init", "kernels", "geometric lengthscale at the start of a registration (m)",
                0.005, 2.0},
    p.ell_init);
  v(SettingInfo{"ell_min", "kernels", "smallest geometric lengthscale of the annealing (m)", 0.002,
                1.0},
    p.ell_min);
  v(SettingInfo{"ell_first_frame", "kernels",
                "lengthscale of a registration without a motion guess (first frame, recovery) (m)",
                0.005, 3.0},
    p.ell_first_frame);
  v(SettingInfo{"ell_prior", "kernels",
                "lengthscale of a registration from a confident feature prior (m): its guess is "
                "within millimetres, no wide basin is needed",
                0.002, 2.0},
    p.ell_prior);
  v(SettingInfo{"ell_min_ratio_with_ignored", "kernels",
                "a registration whose frame or reference has pixels of ignore_classes left out "
                "anneals to ell_min times this (1: ell_min)",
                0.01, 1.0},
    p.ell_min_ratio_with_ignored);
  v(SettingInfo{"sigma", "kernels", "geometric kernel amplitude s", 0.001, 10.0}, p.sigma);
  v(SettingInfo{"sp_ratio", "kernels",
                "a pair counts only if its kernel product exceeds this fraction of the largest "
                "product of the enabled kernels; 0: sp_thres (the paper's form) instead",
                0.0, 0.99},
    p.sp_ratio);
  v(SettingInfo{"sp_thres", "kernels",
                "with sp_ratio 0: a pair counts only if its kernel product exceeds this", 0.0, 0.5},
    p.sp_thres);
  v(SettingInfo{"use_color", "kernels", "colour kernel on (5-D: B, G, R, two image gradients)"},
    p.use_color);
  v(SettingInfo{"color_ell", "kernels", "colour lengthscale", 0.01, 5.0}, p.color_ell);
  v(SettingInfo{"color_sigma", "kernels", "colour kernel amplitude", 0.01, 10.0}, p.color_sigma);
  v(SettingInfo{"use_semantics", "kernels",
                "semantic kernel on (needs segmentation images with semantic_classes)"},
    p.use_semantics);
  v(SettingInfo{"semantic_cross_weight", "kernels",
                "weight of a pair of different classes against one of the same class (0: a gate)",
                0.0, 1.0},
    p.semantic_cross_weight);
  v(SettingInfo{"semantic_sigma", "kernels", "semantic kernel amplitude", 0.01, 10.0},
    p.semantic_sigma);
  // Step method and schedule
  v(SettingInfo{"step_method", "solver",
                "procrustes: closed-form MM steps, coarse-to-fine; reference: the paper's"},
    p.step_method);
  v(SettingInfo{"max_iterations", "solver", "iteration cap of a registration", 10, 100000},
    p.max_iterations);
  v(SettingInfo{"eps_2", "solver", "converged when |log(increment)| < eps_2 (at ell_min)", 1e-9,
                1e-1},
    p.eps_2);
  v(SettingInfo{"schedule_decay", "solver", "procrustes: lengthscale factor from level to level",
                0.1, 0.99},
    p.schedule_decay);
  v(SettingInfo{"level_tolerance", "solver",
                "procrustes: a coarse level ends when |step| < level_tolerance * ell", 1e-6, 1.0},
    p.level_tolerance);
  v(SettingInfo{"subsample_coarse_levels", "solver",
                "procrustes: every k-th point above ell_min, k ~ ell / ell_min"},
    p.subsample_coarse_levels);
  v(SettingInfo{"max_overrelaxation", "solver",
                "procrustes: largest stretch of the step while F keeps rising", 1.0, 3.0},
    p.max_overrelaxation);
  v(SettingInfo{"max_level_iterations", "solver",
                "procrustes: iterations after which a coarse level ends", 1, 10000},
    p.max_level_iterations);
  v(SettingInfo{"max_source_points", "solver",
                "procrustes: most points of the current cloud a registration sums over (spread "
                "evenly; the reference cloud keeps all of its points); 0: all, else >= 500",
                0, 1000000},
    p.max_source_points);
  v(SettingInfo{"newton_at_ell_min", "solver",
                "procrustes: Newton steps at ell_min where the curvature allows"},
    p.newton_at_ell_min);
  v(SettingInfo{"decay_rate", "solver", "reference: lengthscale decay factor", 0.01, 1.0},
    p.decay_rate);
  v(SettingInfo{"decay_start", "solver", "reference: iterations before the first decay", 0, 100000},
    p.decay_start);
  v(SettingInfo{"first_frame_decay_rate", "solver",
                "reference: decay factor without a motion guess", 0.01, 1.0},
    p.first_frame_decay_rate);
  v(SettingInfo{"first_frame_decay_start", "solver",
                "reference: iterations before the first decay without a motion guess", 0, 100000},
    p.first_frame_decay_start);
  v(SettingInfo{"indicator_window", "solver",
                "reference: iterations per window of the annealing indicator", 1, 10000},
    p.indicator_window);
  v(SettingInfo{"indicator_tolerance", "solver",
                "reference: decay when two windows' pair counts agree within this", 0.0, 1.0},
    p.indicator_tolerance);
  v(SettingInfo{"min_step", "solver", "reference: smallest Taylor step", 1e-8, 1e-1}, p.min_step);
  v(SettingInfo{"max_step", "solver", "reference: largest Taylor step", 1e-3, 5.0}, p.max_step);
  // Photometric stage
  v(SettingInfo{"photometric_rotation", "photometric",
                "refine the rotation from the colour image after CVO"},
    p.photometric_rotation);
  v(SettingInfo{"photometric_iterations", "photometric", "Gauss-Newton iterations per image level",
                1, 100},
    p.photometric_iterations);
  v(SettingInfo{"photometric_max_correction", "photometric",
                "larger rotation corrections (deg) are refused", 0.01, 30.0},
    p.photometric_max_correction);
  v(SettingInfo{"photometric_translation", "photometric",
                "keep the stage's translation too (stereo: depth and image are simultaneous)"},
    p.photometric_translation);
  v(SettingInfo{"photometric_tracks", "photometric",
                "the feature prior's inlier tracks join the stage (stereo: depth and image are "
                "simultaneous)"},
    p.photometric_tracks);
  // Where the sums run
  v(SettingInfo{"backend", "backend", "auto: the GPU when one is usable, else the CPU"}, p.backend);
  v(SettingInfo{"num_threads", "backend", "CPU threads (0: all cores)", 0, 1024}, p.num_threads);
  v(SettingInfo{"adaptive_threads", "backend",
                "one thread while the frames get no more than about one core (a CPU shared with "
                "other processes), all again when more is free"},
    p.adaptive_threads);
  // Tracking judgement
  v(SettingInfo{"min_cosine", "tracking", "a registration below this cosine is not trusted", 0.0,
                0.99},
    p.min_cosine);
  v(SettingInfo{"min_tracking_points", "tracking", "fewest points a frame needs to be registered",
                1, 100000},
    p.min_tracking_points);
  v(SettingInfo{"max_linear_speed", "tracking", "faster motion (m/s) is implausible", 0.01, 200.0},
    p.max_linear_speed);
  v(SettingInfo{"max_angular_speed", "tracking", "faster turning (deg/s) is implausible", 1.0,
                3600.0},
    p.max_angular_speed);
  v(SettingInfo{"lost_frame_policy", "tracking", "what a lost frame publishes"},
    p.lost_frame_policy);
  v(SettingInfo{"max_lost_frames", "tracking",
                "lost frames in a row before tracking restarts (2 where tracks find no motion)", 0,
                1000},
    p.max_lost_frames);
  // Keyframes
  v(SettingInfo{"reference", "odometry",
                "register each frame to the keyframe or to the previous good frame"},
    p.reference);
  v(SettingInfo{"keyframe_cosine_ratio", "odometry",
                "a new keyframe when the cosine falls below this fraction of the first one "
                "registered to the keyframe",
                0.0, 0.99},
    p.keyframe_cosine_ratio);
  v(SettingInfo{"keyframe_max_translation", "odometry",
                "a new keyframe when the camera has moved farther from it (m)", 0.001, 100.0},
    p.keyframe_max_translation);
  v(SettingInfo{"keyframe_max_rotation", "odometry",
                "a new keyframe when the camera has turned more since it (deg)", 0.01, 180.0},
    p.keyframe_max_rotation);
  // Motion guess and the feature tracks' check
  v(SettingInfo{"initial_guess", "guess",
                "where a registration starts: auto, constant_velocity, features or identity"},
    p.initial_guess);
  v(SettingInfo{"forget_motion", "guess",
                "drop the motion history before every frame (as after a restart; for tests)"},
    p.forget_motion);
  v(SettingInfo{"min_prior_inliers", "guess",
                "the feature prior's tracks judge registrations with this many inliers", 4, 100000},
    p.min_prior_inliers);
  v(SettingInfo{"min_prior_inlier_ratio", "guess",
                "... and it is the guess with this fraction of its tracks as inliers", 0.0, 1.0},
    p.min_prior_inlier_ratio);
  v(SettingInfo{"guess_disagreement_translation", "guess",
                "prior and constant velocity further apart than this (m) are both tried (the "
                "second unless the first agrees with every track)",
                0.001, 100.0},
    p.guess_disagreement_translation);
  v(SettingInfo{"guess_disagreement_rotation", "guess",
                "... or turned further apart than this (deg)", 0.01, 180.0},
    p.guess_disagreement_rotation);
  v(SettingInfo{"track_agreement_px", "tracking",
                "a feature track agrees with a registration within this reprojection error (px)",
                0.1, 100.0},
    p.track_agreement_px);
  v(SettingInfo{"min_track_agreement", "tracking",
                "a registration the tracks judge is trusted only if this fraction of them agrees",
                0.0, 1.0},
    p.min_track_agreement);
  v(SettingInfo{"max_track_rotation_gap", "tracking",
                "a registration the tracks judge is trusted only if it turns within this (deg) of "
                "their motion over the step (twice this where the segmentation left pixels out)",
                0.001, 180.0},
    p.max_track_rotation_gap);
  v(SettingInfo{"moving_track_agreement", "moving",
                "while something moved in view lately, and until a frame since the start is "
                "trusted, this fraction of the tracks must agree with a registration (at least "
                "min_track_agreement)",
                0.0, 1.0},
    p.moving_track_agreement);
  v(SettingInfo{"tracked_cosine_ratio", "tracking",
                "a registration the tracks judge needs a cosine of only this fraction of "
                "min_cosine",
                0.0, 1.0},
    p.tracked_cosine_ratio);
  v(SettingInfo{"weak_cosine", "tracking",
                "a registration below this cosine is trusted only if the tracks' median error is "
                "within 0.6 track_agreement_px (0: no such bound)",
                0.0, 1.0},
    p.weak_cosine);
  v(SettingInfo{"moving_min_px", "moving",
                "a second motion among the tracks that moves them at least this far (px) from "
                "where the first puts them is an object moving on its own",
                0.0, 1000.0},
    p.moving_min_px);
  v(SettingInfo{"moving_region_px", "moving",
                "points within this distance (px) of the tracks of a second motion (an object "
                "moving through the view) are left out of the cloud and the photometric stage",
                0.0, 1000.0},
    p.moving_region_px);
  v(SettingInfo{"motion_split_ratio", "moving",
                "of two motions among the tracks at similar depths the scene follows the one with "
                "more tracks when the other has fewer than this fraction of them",
                0.0, 1.0},
    p.motion_split_ratio);
  v(SettingInfo{"motion_split_depth_ratio", "moving",
                "of two motions among the tracks the scene follows the farther one's when its "
                "tracks' median depth is this many times the other's",
                1.0, 100.0},
    p.motion_split_depth_ratio);
}

}  // namespace cvo
