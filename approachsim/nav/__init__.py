"""Navigation: strapdown INS, baro damping loop, error-state EKF and its robust and U-D variants, monitors."""
