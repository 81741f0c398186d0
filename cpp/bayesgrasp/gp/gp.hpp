// Umbrella header for the gp concept: kernels, ExactGP, SparseGP (FITC), IndependentOutputsGP.
// The API is described at the top of gaussian_process.hpp.
#pragma once

#include "bayesgrasp/gp/exact_gp.hpp"
#include "bayesgrasp/gp/gaussian_process.hpp"
#include "bayesgrasp/gp/independent_outputs_gp.hpp"
#include "bayesgrasp/gp/kernel.hpp"
#include "bayesgrasp/gp/sparse_gp.hpp"
