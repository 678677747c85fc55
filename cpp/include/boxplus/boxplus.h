// Everything a C++ user of boxplus needs: manifolds, noise models, the problem.
#pragma once

#include "boxplus/errors.h"
#include "boxplus/factors/pose/prior.h"
#include "boxplus/loss.h"
#include "boxplus/manifolds.h"
#include "boxplus/noise.h"
#include "boxplus/problem.h"
#include "boxplus/progress.h"
#include "boxplus/solver_options.h"
#include "boxplus/version.h"
