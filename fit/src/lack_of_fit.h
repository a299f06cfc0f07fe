// Lack of fit along the radius: structure in a radial fit's residuals that noise does not make
// (runs of one sign over many bins). A model exact to transport that leaves such structure is not
// the sample's transport: a slab thinner than the profile's reach, a beam or lens blur wider than a
// pencil, veiling glare, another eta or g. Internal to lucent_fit.
#pragma once

#include <string>
#include <vector>

namespace lucent::fit::detail {

/// The standardised residuals of one channel's radial bins, in order of radius, grouped into
/// contiguous segments of equal count.
struct RadialStructure {
  int bins = 0;
  /// The noise scale of the residuals from their first differences (1.4826 median |e_i+1 - e_i| /
  /// sqrt 2): white noise keeps it, a smooth misfit cancels out of it.
  double scale = 1;
  /// sum over segments of (sum of the segment's residuals)^2 / (count scale^2): chi^2 with one
  /// degree of freedom per segment for residuals that are noise alone.
  double q = 0;
  /// q as a standard normal deviate (Wilson-Hilferty): how far beyond noise the structure is.
  double z = 0;
  std::vector<double> r_mm;  ///< each segment's middle radius, mm
  /// each segment's sum of residuals over the standard deviation noise gives that sum (data and
  /// model): a standard normal deviate where the model holds
  std::vector<double> mean;
  int segments() const { return int(mean.size()); }
};

/// Structure of n residuals e (model above data is positive) at radii r (ascending); empty (no
/// segments) below 24 bins, where a few segments cannot be told from the fitted parameters.
/// model_share (optional): per residual, the part of its standard error that is the model's own
/// (the transport table's Monte Carlo noise, in units of the residual's total error). That noise
/// is smooth along the radius (one table entry spans many bins), so it is counted as fully
/// correlated within a segment, and what noise alone makes grows by it.
RadialStructure radial_structure(const std::vector<double>& r, const double* e, int n,
                                 const double* model_share = nullptr);

/// The bar for z: measured on good fits (semi-infinite Monte Carlo profiles and simulated camera
/// captures, the model exact), so that a good fit is refused less than 1 time in 100 (README, "Real
/// benches": the false-alarm rates).
inline constexpr double kMaxStructureZ = 4.0;

/// One sentence naming what the pattern points to, for the fit's refusal: "the far tail falls
/// faster than a semi-infinite sample allows: is it thinner than about X mm? give --thickness-mm",
/// a beam or blur wider than a pencil, glare, or eta / g / the model.
std::string lack_of_fit_reason(const RadialStructure& s, char channel);

}  // namespace lucent::fit::detail

namespace lucent::fit::detail {

/// The thinnest slab whose profile stays within `tolerance` (relative) of the semi-infinite
/// sample's out to reach_mm, for a medium of these coefficients, by diffusion theory (the
/// standard dipole and its slab's image series, extrapolated boundaries): a fit that assumed a
/// semi-infinite sample holds only for samples thicker than this. mm; infinity when even 10 m is
/// not enough.
double thinnest_semi_infinite_mm(double sigma_a, double sigma_s_reduced, double eta, double reach_mm,
                                 double tolerance);

}  // namespace lucent::fit::detail
