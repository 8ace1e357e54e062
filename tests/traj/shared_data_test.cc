// Every text trajectory file in ../shared/data is read with the options docs/data.md documents, and
// gives the number of poses its data set's own SOURCE.md (shipped with the data) states and the first/last stamps printed in the file
// (converted to ns exactly, independently, with Python's Decimal when this table was made).
#include <string>

#include <gtest/gtest.h>

#include "cheval/traj/io.h"
#include "cheval/traj/summary.h"
#include "../support/test_data.h"

namespace cheval::traj {
namespace {

struct SharedFile {
  const char* path;          // under the shared data folder
  const char* format;        // --format
  const char* columns;       // --columns ("" = none)
  const char* kitti_times;   // --kitti-times ("" = none)
  Eigen::Index poses;        // rows, as SOURCE.md states
  int64_t first_stamp_ns;    // first stamp of the file (KITTI: of the times file)
  int64_t last_stamp_ns;
  Eigen::Index non_increasing;  // rows whose stamp is <= the previous one
};

const SharedFile kSharedFiles[] = {
    {"blackbird_imo/clover_yawForward_maxSpeed5p0/test/stamped_groundtruth_imu.txt", "tumv", "", "", 3000, 1525745865001655340LL, 1525745894991626740LL, 0},
    {"blackbird_imo/clover_yawForward_maxSpeed5p0/train/stamped_groundtruth_imu.txt", "tumv", "", "", 9100, 1525745925001598120LL, 1525746015991511345LL, 0},
    {"blackbird_imo/clover_yawForward_maxSpeed5p0/val/stamped_groundtruth_imu.txt", "tumv", "", "", 3000, 1525745895001626730LL, 1525745924991598129LL, 0},
    {"cerberus_a1/output/dataset11_0903/vilo_wlwb_forward_backward.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 791, 1630698702290569216LL, 1630698754960401664LL, 0},
    {"cerberus_a1/output/dataset11_0903/vilo_wlwb_forward_backward.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 791, 1630698702290569216LL, 1630698754960401664LL, 0},
    {"cerberus_a1/output/dataset11_0903/vilo_wlwob_forward_backward.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 795, 1630698702290569216LL, 1630698755227084288LL, 0},
    {"cerberus_a1/output/dataset11_0903/vilo_wlwob_forward_backward.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 795, 1630698702290569216LL, 1630698755227084288LL, 0},
    {"cerberus_a1/output/dataset11_0903/vio.csv", "vins", "", "", 794, 1630698702290569216LL, 1630698755160414208LL, 0},
    {"cerberus_a1/output/dataset1_0903/vilo_with_leg_bias_0907_best.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"cerberus_a1/output/dataset1_0903/vilo_with_leg_bias_0907_best.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_0903_forward_reidx_with_gt.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_0903_forward_reidx_with_gt.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_wlwb_0903_forward_backward_reidx_with_gt.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 862, 1630698702290569216LL, 1630698759694125056LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_wlwb_0903_forward_backward_reidx_with_gt.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 862, 1630698702290569216LL, 1630698759694125056LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_wlwb_0903_forward_reidx_with_gt.csv", "csv", "t_ns,px,py,pz,qw,qx,qy,qz,vx,vy,vz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"cerberus_a1/output/dataset1_0903/vio_wlwb_0903_forward_reidx_with_gt.csv", "csv", "t_ns,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 559, 1630698550081125632LL, 1630698587283393024LL, 0},
    {"crazyflie_brushless_idsia/melon_20251017_run5.csv", "csv", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz", "", 6500, 0LL, 64990000000LL, 0},
    {"crazyflie_brushless_idsia/melon_20251017_run5.csv", "csv", "t,_,_,_,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 6500, 0LL, 64990000000LL, 0},
    {"crazyflie_brushless_idsia/random1_20251017_run1.csv", "csv", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz", "", 6000, 0LL, 59990000000LL, 0},
    {"crazyflie_brushless_idsia/random1_20251017_run1.csv", "csv", "t,_,_,_,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 6000, 0LL, 59990000000LL, 0},
    {"crazyflie_brushless_idsia/square_20251017_run1.csv", "csv", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz", "", 1900, 0LL, 18990000000LL, 0},
    {"crazyflie_brushless_idsia/square_20251017_run1.csv", "csv", "t,_,_,_,_,_,_,_,_,_,_,_,_,_,px,py,pz", "", 1900, 0LL, 18990000000LL, 0},
    {"dido/csv/circle_a_1.5_v_2.5_r_1.5_2022-02-21-23-46-22.csv", "csv", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz", "", 14616, 1645458383129590000LL, 1645458419664650000LL, 0},
    {"dido/csv/eight_a_2.2_v_3.5_rx_1.8_2022-02-22-11-50-24.csv", "csv", "t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz", "", 15548, 1645501825817970000LL, 1645501864684950000LL, 0},
    {"evo/KITTI_00_ORB.txt", "kitti", "", "evo/KITTI_00_gt_times.txt", 4541, 0LL, 470581600000LL, 0},
    {"evo/KITTI_00_SPTAM.txt", "kitti", "", "evo/KITTI_00_gt_times.txt", 4541, 0LL, 470581600000LL, 0},
    {"evo/KITTI_00_gt.txt", "kitti", "", "evo/KITTI_00_gt_times.txt", 4541, 0LL, 470581600000LL, 0},
    {"evo/V102.txt", "tum", "", "", 807, 1403715529112143517LL, 1403715609312143564LL, 4},
    {"evo/V102_groundtruth.csv", "euroc", "", "", 16702, 1403715524907143168LL, 1403715608412143104LL, 0},
    {"evo/fr2_desk_ORB.txt", "tum", "", "", 2893, 1311868164363181000LL, 1311868263185529000LL, 0},
    {"evo/fr2_desk_ORB_kf_mono.txt", "tum", "", "", 157, 1311868171131477000LL, 1311868262150528000LL, 0},
    {"evo/fr2_desk_groundtruth.txt", "tum", "", "", 20957, 1311868163869700000LL, 1311868263234200000LL, 1},
    {"evo/freiburg1_xyz-ORB_kf_mono.txt", "tum", "", "", 32, 1305031110043299000LL, 1305031128679282000LL, 0},
    {"evo/freiburg1_xyz-groundtruth.txt", "tum", "", "", 3000, 1305031098665900000LL, 1305031128755500000LL, 0},
    {"evo/freiburg1_xyz-rgbdslam.txt", "tum", "", "", 788, 1305031102160407000LL, 1305031128722976000LL, 0},
    {"evo/freiburg1_xyz-rgbdslam_drift.txt", "tum", "", "", 788, 1305031102160407000LL, 1305031128722976000LL, 0},
    {"evo/freiburg1_xyz-rgbdslam_drift_short.txt", "tum", "", "", 40, 1305031102160407000LL, 1305031103562651000LL, 0},
    {"evo/georeferenced.tum", "tum", "", "", 1000, 1706282470098386526LL, 1706283818898386717LL, 0},
    {"evo_v101_openvins/V101_openvins.txt", "tum", "", "", 2776, 1403715278862139940LL, 1403715418762140036LL, 0},
    {"icub_diligent_kio/com-sinusoid.csv", "csv", "t,px,py,pz,roll,pitch,yaw", "", 2004, 1602266022845577000LL, 1602266042981183000LL, 0},
    {"icub_diligent_kio/walking.csv", "csv", "t,px,py,pz,roll,pitch,yaw", "", 1188, 1602256052650440000LL, 1602256064644009000LL, 0},
    {"kimera_vio_evaluation/evaluation/tests/test_results/V1_01_easy/Euroc/traj_pgo.csv", "euroc", "", "", 51, 1403715274212143104LL, 1403715284212143104LL, 0},
    {"kimera_vio_evaluation/evaluation/tests/test_results/V1_01_easy/Euroc/traj_vio.csv", "euroc", "", "", 52, 1403715274012143104LL, 1403715284212143104LL, 0},
    {"ov_data/euroc_mav/MH_01_easy.txt", "tum", "", "", 36382, 1403636580838560000LL, 1403636762743560000LL, 0},
    {"ov_data/euroc_mav/MH_05_difficult.csv", "euroc", "", "", 22212, 1403638519492829440LL, 1403638630547829504LL, 0},
    {"ov_data/euroc_mav/V1_01_easy.csv", "euroc", "", "", 2895, 1403715273262142976LL, 1403715417962142976LL, 0},
    {"ov_data/euroc_mav/V1_02_medium.csv", "euroc", "", "", 16702, 1403715524907143168LL, 1403715608412143104LL, 0},
    {"ov_data/euroc_mav/V2_02_medium.csv", "euroc", "", "", 23091, 1413393887225760512LL, 1413394002675760384LL, 0},
    {"ov_data/rpng_plane/table_01.csv", "euroc", "", "", 8156, 1662915732374960384LL, 1662915813924882688LL, 0},
    {"ov_data/tum_vi/dataset-room1_512_16.csv", "euroc", "", "", 16541, 1520530308189679351LL, 1520530449214678351LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_mono/laptop_vio_mono_MH_01/stamped_traj_estimate.txt", "tum", "", "", 3660, 1403636579763555527LL, 1403636762713555574LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_mono/laptop_vio_mono_MH_05/stamped_traj_estimate.txt", "tum", "", "", 2245, 1403638518077829599LL, 1403638630277829409LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_mono/laptop_vio_mono_V2_02/stamped_traj_estimate.txt", "tum", "", "", 2225, 1413393889255760431LL, 1413394000455760479LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_stereo/laptop_vio_stereo_MH_01/stamped_traj_estimate.txt", "tum", "", "", 3682, 1403636579763555527LL, 1403636763813555479LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_stereo/laptop_vio_stereo_MH_05/stamped_traj_estimate.txt", "tum", "", "", 2273, 1403638518077829599LL, 1403638631677829504LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_mono_stereo/laptop/vio_stereo/laptop_vio_stereo_V2_02/stamped_traj_estimate.txt", "tum", "", "", 2283, 1413393889255760431LL, 1413394003355760574LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate0.txt", "tum", "", "", 264, 1403715529262140000LL, 1403715600662140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate1.txt", "tum", "", "", 269, 1403715529262140000LL, 1403715600812140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate2.txt", "tum", "", "", 265, 1403715529262140000LL, 1403715600812140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate3.txt", "tum", "", "", 269, 1403715529262140000LL, 1403715600862140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate4.txt", "tum", "", "", 268, 1403715529262140000LL, 1403715600812140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate5.txt", "tum", "", "", 277, 1403715529262140000LL, 1403715600862140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate6.txt", "tum", "", "", 268, 1403715529262140000LL, 1403715600662140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate7.txt", "tum", "", "", 271, 1403715529262140000LL, 1403715600662140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate8.txt", "tum", "", "", 270, 1403715529262140000LL, 1403715600862140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_ba/laptop_vislam_ba_V1_02/stamped_ba_estimate9.txt", "tum", "", "", 268, 1403715529262140000LL, 1403715601062140000LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_groundtruth.txt", "tum", "", "", 16702, 1403715524907143116LL, 1403715608412142992LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate0.txt", "tum", "", "", 1355, 1403715540412142992LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate1.txt", "tum", "", "", 1367, 1403715539812143087LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate2.txt", "tum", "", "", 1361, 1403715540112143040LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate3.txt", "tum", "", "", 1397, 1403715538312143087LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate4.txt", "tum", "", "", 1366, 1403715539862143040LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate5.txt", "tum", "", "", 1452, 1403715535562143087LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate6.txt", "tum", "", "", 1366, 1403715539862143040LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate7.txt", "tum", "", "", 1437, 1403715536312143087LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate8.txt", "tum", "", "", 1417, 1403715537312143087LL, 1403715608112143040LL, 0},
    {"rpg_trajectory_evaluation/results/euroc_vislam_mono/laptop/vislam_rp/laptop_vislam_rp_V1_02/stamped_traj_estimate9.txt", "tum", "", "", 1360, 1403715540162142992LL, 1403715608112143040LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3423e45/results/MH03vins_result_loop.csv", "vins", "", "", 831, 1403637155438318848LL, 1403637262738318848LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3423e45/results/MH03vins_result_no_loop.csv", "vins", "", "", 1112, 1403637154338319104LL, 1403637265438318848LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3423e45/results/MH04vins_result_loop.csv", "vins", "", "", 586, 1403638151145096960LL, 1403638226345096960LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3423e45/results/MH04vins_result_no_loop.csv", "vins", "", "", 792, 1403638149745096960LL, 1403638228845096960LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3ef25a0/results/vins_result_loop.csv", "vins", "", "", 594, 1403638541927829504LL, 1403638630727829504LL, 0},
    {"vins_mono_outputs/OkayManXi_VINS-Mono/commit_3ef25a0/results/vins_result_no_loop.csv", "vins", "", "", 909, 1403638540827829504LL, 1403638631627829504LL, 0},
    {"vins_mono_outputs/Yixin-F_vins_mono_noted/output/vins_result_loop.csv", "vins", "", "", 707, 1403638524277829376LL, 1403638630777829376LL, 0},
    {"vins_mono_outputs/Yixin-F_vins_mono_noted/output/vins_result_no_loop.csv", "vins", "", "", 1087, 1403638523077829632LL, 1403638631677829632LL, 0},
    {"vins_mono_outputs/xygxgn_VINS-Fusion/output/vins_result_no_loop.csv", "vins", "", "", 1817, 1403636582163555328LL, 1403636763763555584LL, 0},
    {"vio_perf/commit_b4a7c3f/cppt/MH_05.tum", "tum", "", "", 2184, 1403638522527829409LL, 1403638631677829504LL, 0},
    {"vio_perf/commit_b4a7c3f/cppt/V2_02.tum", "tum", "", "", 2274, 1413393889705760479LL, 1413394003355760574LL, 0},
    {"vio_perf/commit_b4a7c3f/ice_ba_mono/MH_05.tum", "tum", "", "", 2272, 1403638518190170050LL, 1403638631731358051LL, 3},
    {"vio_perf/commit_b4a7c3f/ice_ba_mono/V2_02.tum", "tum", "", "", 2346, 1413393885797096968LL, 1413394003051702738LL, 5},
    {"vio_perf/commit_b4a7c3f/ice_ba_stereo/MH_05.tum", "tum", "", "", 2271, 1403638518229931831LL, 1403638631728451014LL, 4},
    {"vio_perf/commit_b4a7c3f/ice_ba_stereo/V2_02.tum", "tum", "", "", 2346, 1413393885797473907LL, 1413394003047118664LL, 40},
    {"vio_perf/commit_b4a7c3f/svo2.0/MH_05.tum", "tum", "", "", 2188, 1403638522410295486LL, 1403638631720223904LL, 0},
    {"vio_perf/commit_b4a7c3f/svo2.0/V2_02.tum", "tum", "", "", 2270, 1413393889605573654LL, 1413394003036594152LL, 0},
    {"vio_perf/commit_b4a7c3f/vins/MH_05.tum", "tum", "", "", 1095, 1403638522501309156LL, 1403638631742417097LL, 0},
    {"vio_perf/commit_b4a7c3f/vins/V2_02.tum", "tum", "", "", 1136, 1413393889703724623LL, 1413394003050278187LL, 0},
    {"vio_perf/commit_b792fd3/ORB_SLAM2/MH_05.tum", "tum", "", "", 2057, 1403638518177830000LL, 1403638631677830000LL, 0},
    {"vio_perf/commit_b792fd3/ORB_SLAM2/V2_02.tum", "tum", "", "", 2273, 1413393886055760000LL, 1413394003355761000LL, 0},
    {"vio_perf/commit_b792fd3/ORB_SLAM2_lc/MH_05.tum", "tum", "", "", 2108, 1403638518177830000LL, 1403638631677830000LL, 0},
    {"vio_perf/commit_b792fd3/ORB_SLAM2_lc/V2_02.tum", "tum", "", "", 2198, 1413393886105761000LL, 1413394003355761000LL, 0},
    {"vio_perf/commit_b792fd3/vins_lc/MH_05.tum", "tum", "", "", 719, 1403638523477829456LL, 1403638630777829409LL, 0},
    {"vio_perf/commit_b792fd3/vins_lc/V2_02.tum", "tum", "", "", 1043, 1413393890855760574LL, 1413394000555760384LL, 0},
};

class SharedDataTest : public ::testing::TestWithParam<SharedFile> {};

TEST_P(SharedDataTest, ReadsPosesAndStampsAsStated) {
  CHEVAL_REQUIRE_SHARED_DATA();
  const SharedFile& file = GetParam();
  const std::string root = cheval::testing::SharedDataDir() + "/";
  ReadOptions options;
  options.format = *FormatFromString(file.format);
  if (*file.columns != '\0') options.columns = ColumnMap::Parse(file.columns);
  if (*file.kitti_times != '\0') options.kitti_times_path = root + file.kitti_times;
  const Trajectory trajectory = ReadTrajectory(root + file.path, options);
  const TrajectorySummary summary = Summarize(trajectory.View());
  EXPECT_EQ(summary.poses, file.poses);
  EXPECT_EQ(summary.first_stamp_ns, file.first_stamp_ns);
  EXPECT_EQ(summary.last_stamp_ns, file.last_stamp_ns);
  EXPECT_EQ(summary.non_increasing_stamps, file.non_increasing);
  // Files with a plain format must also be recognised by auto-detection as that format.
  const std::string format = file.format;
  if (format != "csv") {
    ReadOptions automatic;
    automatic.kitti_times_path = options.kitti_times_path;
    Format detected = Format::kAuto;
    const Trajectory again = ReadTrajectory(root + file.path, automatic, &detected);
    EXPECT_EQ(detected, options.format) << file.path;
    EXPECT_EQ(again.size(), trajectory.size());
  }
}

std::string TestName(const ::testing::TestParamInfo<SharedFile>& info) {
  std::string name = std::to_string(info.index) + "_" + info.param.path;
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(AllFiles, SharedDataTest, ::testing::ValuesIn(kSharedFiles), TestName);

}  // namespace
}  // namespace cheval::traj
