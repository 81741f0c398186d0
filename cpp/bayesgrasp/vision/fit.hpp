// A model's dense surface samples with their radius grid, the scene-to-model distances, and the
// fit measures of a registration: fitness, RMSE, the fitting error delta_i and phi(delta_i) of
// Eq. 4.1, the up cosine and the hypothesis selection cost.
#pragma once

#include <vector>

#include "bayesgrasp/vision/oriented_cloud.hpp"
#include "bayesgrasp/vision/registration_options.hpp"

namespace bayesgrasp::vision {

/// A model's dense surface samples (exact normals) and a grid over them with the radius of the
/// longest distance the fit measures and ICP look at.
struct DenseModel {
  OrientedCloud samples;
  RadiusGrid grid;
};

/// For each scene point p: the nearest dense sample to T p within the grid's radius (index, -1 if
/// none) and its distance (infinity if none).
void nearest_samples(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, const Iso3& T,
                     std::vector<double>& distance, std::vector<int>& index);

struct Fit {
  double fitness = 0;  // fraction of scene points within tau
  double rmse = 0;     // RMS distance of those, m
  double delta = 0;    // sqrt(mean min(d_i, tau)^2), m: Eq. 4.1's delta_i
};

/// The fit of the scene points moved by T (scene -> model) to the model, with cut-off tau (m).
Fit measure_fit(const DenseModel& model, const std::vector<Eigen::Vector3d>& scene, const Iso3& T, double tau);

/// phi(delta) = exp(-delta^2 / (2 sigma^2)), Eq. 4.1's P(O_i | delta_i) up to normalisation.
double phi(double delta, double sigma);

/// Cosine between the model's +z mapped to the scene and `up` (unit), for T scene -> model.
double up_cosine(const Iso3& T, const Eigen::Vector3d& up);

/// Hypothesis selection cost: delta / tau plus, with the up prior, weight (1 - up cosine) / 2.
double selection_cost(const Fit& fit, const Iso3& T, double tau, const Eigen::Vector3d& up, const UpPrior& prior);

}  // namespace bayesgrasp::vision
