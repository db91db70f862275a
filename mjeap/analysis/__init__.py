"""Analysis on simulations: frequency response, identification, calibration, the stability map."""
