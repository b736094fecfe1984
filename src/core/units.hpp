#pragma once
// ibrod's one units module. Inside the code every quantity is in the gram–ångström–second system
// (MODEL §1): length Å, mass g, time s, charge in units of the elementary charge e. Users see
// natural units (Å, ns, µs, kT, mol/L, poise, erg·cm, dyn); convert only at the boundary, with
// these factors: value_internal = value_user * factor.
#include <cmath>
#include <numbers>

namespace ibrod::units {

// base units (internal)
inline constexpr double angstrom = 1.0;
inline constexpr double gram = 1.0;
inline constexpr double second = 1.0;

// lengths
inline constexpr double cm = 1e8 * angstrom;
inline constexpr double nm = 10.0 * angstrom;
// times
inline constexpr double ns = 1e-9 * second;
inline constexpr double us = 1e-6 * second;
// derived CGS units
inline constexpr double dyn = gram * cm / (second * second);  ///< 1e8 g Å s⁻²
inline constexpr double pN = 1e-7 * dyn;                      ///< piconewton, 10 g Å s⁻²
inline constexpr double erg = dyn * cm;                       ///< 1e16 g Å² s⁻²
inline constexpr double erg_cm = erg * cm;             ///< bending modulus unit, 1e24 g Å³ s⁻²
inline constexpr double poise = gram / (cm * second);  ///< 1e-8 g Å⁻¹ s⁻¹
inline constexpr double g_per_cm3 = gram / (cm * cm * cm);  ///< 1e-24 g Å⁻³

// physical constants
inline constexpr double boltzmann = 1.380649e-16 * erg;  ///< k_B per kelvin, g Å² s⁻² K⁻¹
/// vacuum permittivity in e² s² g⁻¹ Å⁻³ (MODEL §1)
inline constexpr double vacuum_permittivity = 3.45e-7;

/// thermal energy kT at temperature T (K), g Å² s⁻²; 414.2 at 300 K
inline constexpr double kT(double temperature_K) { return boltzmann * temperature_K; }

/// Debye screening parameter κ (Å⁻¹) for monovalent salt at concentration Cs (mol/L): MODEL §1.
inline double debye_kappa(double salt_M) { return 0.329 * std::sqrt(salt_M); }

/// Bjerrum length e²/(4π ε0 εw kT), Å.
inline double bjerrum_length(double dielectric, double temperature_K) {
  return 1.0 / (4.0 * std::numbers::pi * vacuum_permittivity * dielectric * kT(temperature_K));
}

}  // namespace ibrod::units
