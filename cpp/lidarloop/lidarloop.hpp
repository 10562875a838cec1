#pragma once

// The one header for library users: every public header of every installed target. Link
// lidarloop::app, which links all the others (docs/library.md):
//
//     find_package(lidarloop REQUIRED)
//     target_link_libraries(my_app PRIVATE lidarloop::app)
//
// A program that needs only a lower layer may include that layer's headers and link its target
// instead (e.g. lidarloop/pipeline/loop_detector.hpp and lidarloop::pipeline). Headers under a
// `detail/` folder are internal and not installed. tests/scripts/public_interface_test.sh checks
// that this list names every installed header.

// lidarloop::core: point clouds, projections, histograms, NDT, Scan Context (no I/O)
#include "lidarloop/core/angles.hpp"
#include "lidarloop/core/byte_codec.hpp"
#include "lidarloop/core/descriptor.hpp"
#include "lidarloop/core/descriptor_config.hpp"
#include "lidarloop/core/eigen3x3.hpp"
#include "lidarloop/core/enum_names.hpp"
#include "lidarloop/core/error.hpp"
#include "lidarloop/core/histogram.hpp"
#include "lidarloop/core/kd_tree.hpp"
#include "lidarloop/core/min_gap.hpp"
#include "lidarloop/core/ndt/ndt_cells.hpp"
#include "lidarloop/core/ndt/ndt_config.hpp"
#include "lidarloop/core/ndt/ndt_descriptor.hpp"
#include "lidarloop/core/ndt/ndt_orientation_modes.hpp"
#include "lidarloop/core/ndt/ndt_shape.hpp"
#include "lidarloop/core/ndt/sphere_partition.hpp"
#include "lidarloop/core/number_text.hpp"
#include "lidarloop/core/parameters.hpp"
#include "lidarloop/core/point_cloud.hpp"
#include "lidarloop/core/point_map.hpp"
#include "lidarloop/core/projection.hpp"
#include "lidarloop/core/scancontext/scancontext.hpp"
#include "lidarloop/core/scancontext/scancontext_config.hpp"
#include "lidarloop/core/scancontext/scancontext_distance.hpp"
#include "lidarloop/core/stopwatch.hpp"
#include "lidarloop/core/voxel_grid.hpp"
#include "lidarloop/core/wasserstein.hpp"

// lidarloop::registration: geometric verification of a loop candidate
#include "lidarloop/registration/coarse_alignment.hpp"
#include "lidarloop/registration/compact_prepared_scan.hpp"
#include "lidarloop/registration/icp.hpp"
#include "lidarloop/registration/neighbor_grid.hpp"
#include "lidarloop/registration/point_tree.hpp"
#include "lidarloop/registration/prepared_scan.hpp"
#include "lidarloop/registration/submap.hpp"
#include "lidarloop/registration/verification.hpp"
#include "lidarloop/registration/verification_config.hpp"

// lidarloop::posegraph: pose-graph optimisation with its loops (Ceres)
#include "lidarloop/posegraph/optimiser.hpp"
#include "lidarloop/posegraph/pose_graph.hpp"
#include "lidarloop/posegraph/pose_graph_config.hpp"

// lidarloop::pipeline: descriptor methods, databases, the online loop detector
#include "lidarloop/pipeline/candidate_verification.hpp"
#include "lidarloop/pipeline/cumulative_histograms.hpp"
#include "lidarloop/pipeline/descriptor_database.hpp"
#include "lidarloop/pipeline/descriptor_method.hpp"
#include "lidarloop/pipeline/expanded_scans.hpp"
#include "lidarloop/pipeline/histogram_index.hpp"
#include "lidarloop/pipeline/histogram_method.hpp"
#include "lidarloop/pipeline/loop_detector.hpp"
#include "lidarloop/pipeline/ndt_method.hpp"
#include "lidarloop/pipeline/neighbour_overlaps.hpp"
#include "lidarloop/pipeline/progress_counter.hpp"
#include "lidarloop/pipeline/scancontext_method.hpp"
#include "lidarloop/pipeline/sequence.hpp"
#include "lidarloop/pipeline/similarity_matrix.hpp"

// lidarloop::eval: ground truth, metrics, threshold learning, EM
#include "lidarloop/eval/em.hpp"
#include "lidarloop/eval/ground_truth.hpp"
#include "lidarloop/eval/loop_retrieval.hpp"
#include "lidarloop/eval/metrics.hpp"
#include "lidarloop/eval/pairwise.hpp"
#include "lidarloop/eval/per_scan.hpp"
#include "lidarloop/eval/streamed_pairwise.hpp"
#include "lidarloop/eval/summary.hpp"
#include "lidarloop/eval/threshold_learning.hpp"
#include "lidarloop/eval/trajectory.hpp"

// lidarloop::sim: simulated LiDAR sequences
#include "lidarloop/sim/front_end.hpp"
#include "lidarloop/sim/odometry.hpp"
#include "lidarloop/sim/odometry_drift.hpp"
#include "lidarloop/sim/route.hpp"
#include "lidarloop/sim/scene.hpp"
#include "lidarloop/sim/sensor.hpp"
#include "lidarloop/sim/shapes.hpp"
#include "lidarloop/sim/simulator.hpp"
#include "lidarloop/sim/terrain.hpp"
#include "lidarloop/sim/world.hpp"

// lidarloop::io: readers and writers, datasets, the YAML config
#include "lidarloop/io/colour_map.hpp"
#include "lidarloop/io/config_yaml.hpp"
#include "lidarloop/io/database_file.hpp"
#include "lidarloop/io/dataset.hpp"
#include "lidarloop/io/kitti_bin.hpp"
#include "lidarloop/io/kitti_sequence.hpp"
#include "lidarloop/io/map_files.hpp"
#include "lidarloop/io/map_image.hpp"
#include "lidarloop/io/osnabrueck.hpp"
#include "lidarloop/io/pcd.hpp"
#include "lidarloop/io/plot.hpp"
#include "lidarloop/io/ply.hpp"
#include "lidarloop/io/png.hpp"
#include "lidarloop/io/pose_graph_files.hpp"
#include "lidarloop/io/poses.hpp"
#include "lidarloop/io/prepared_scans_file.hpp"
#include "lidarloop/io/read_error.hpp"
#include "lidarloop/io/results_csv.hpp"
#include "lidarloop/io/ros_messages.hpp"
#include "lidarloop/io/rosbag.hpp"
#include "lidarloop/io/run_record.hpp"
#include "lidarloop/io/scan_reader.hpp"
#include "lidarloop/io/similarity_file.hpp"
#include "lidarloop/io/similarity_image.hpp"
#include "lidarloop/io/xyz.hpp"

// lidarloop::app: the run layer (what each `lidarloop` command does)
#include "lidarloop/app/bench.hpp"
#include "lidarloop/app/describe_run.hpp"
#include "lidarloop/app/descriptor_json.hpp"
#include "lidarloop/app/detection.hpp"
#include "lidarloop/app/evaluation.hpp"
#include "lidarloop/app/evaluation_report.hpp"
#include "lidarloop/app/heap_reuse.hpp"
#include "lidarloop/app/map_building.hpp"
#include "lidarloop/app/metrics_json.hpp"
#include "lidarloop/app/optimisation.hpp"
#include "lidarloop/app/optimisation_report.hpp"
#include "lidarloop/app/progress.hpp"
#include "lidarloop/app/results_folder.hpp"
#include "lidarloop/app/retrieval_evaluation.hpp"
#include "lidarloop/app/run_folder.hpp"
#include "lidarloop/app/run_options.hpp"
#include "lidarloop/app/simulation.hpp"
#include "lidarloop/app/verification_run.hpp"
