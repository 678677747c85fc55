// Everything a C++ user of boxplus needs: manifolds, noise models, the problem.
#pragma once

#include "boxplus/errors.h"
#include "boxplus/factors/make_prior.h"
#include "boxplus/factors/prior.h"
#include "boxplus/manifolds.h"
#include "boxplus/noise.h"
#include "boxplus/problem.h"
#include "boxplus/version.h"
