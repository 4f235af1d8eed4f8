"""Sensor models: IMU, baro, radar altimeter, GPS, pseudolite, and fault injection, all from the Truth record."""
