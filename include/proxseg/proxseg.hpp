// Everything proxseg offers, for users who want one include: the method (core), files (io) and
// measurement (eval). Link proxseg::proxseg (CMake) or `pkg-config --libs proxseg`.
#pragma once
#include <proxseg/core/clustering.hpp>
#include <proxseg/core/database.hpp>
#include <proxseg/core/features.hpp>
#include <proxseg/core/frame.hpp>
#include <proxseg/core/memory.hpp>
#include <proxseg/core/mesh.hpp>
#include <proxseg/core/mrf.hpp>
#include <proxseg/core/pipeline.hpp>
#include <proxseg/core/recognition.hpp>
#include <proxseg/core/registration.hpp>
#include <proxseg/core/render.hpp>
#include <proxseg/core/selection.hpp>
#include <proxseg/core/version.hpp>
#include <proxseg/core/voxels.hpp>
#include <proxseg/eval/clutter.hpp>
#include <proxseg/eval/evaluation.hpp>
#include <proxseg/eval/metrics.hpp>
#include <proxseg/eval/point_mesh.hpp>
#include <proxseg/eval/rec_eval.hpp>
#include <proxseg/eval/scene_eval.hpp>
#include <proxseg/io/cloud_io.hpp>
#include <proxseg/io/database.hpp>
#include <proxseg/io/output.hpp>
#include <proxseg/io/params.hpp>
