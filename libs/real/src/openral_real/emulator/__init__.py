"""A Feetech servo bus emulated byte for byte, its servos moving a simulated arm."""
