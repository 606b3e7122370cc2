#!/usr/bin/env python3
"""Writes weather/sf_year.wea: a synthetic 8760-hour year for San Francisco (fenestra's example data).

Direct-normal and diffuse-horizontal irradiance come from a plain clear-sky attenuation model scaled by a
deterministic day-to-day cloudiness, so the file is reproducible and needs no download. It is example input,
not climate data."""
import math

LAT, LON, MER = 37.62, 122.40, 120.0   # Radiance .wea convention: longitude and meridian in degrees west
DAYS = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]

def cloudiness(day):
    """0 = clear, 1 = overcast; a smooth deterministic sequence with winter more cloudy."""
    season = 0.35 + 0.25 * math.cos(2 * math.pi * (day - 15) / 365)
    wobble = 0.3 * math.sin(day * 1.37) * math.sin(day * 0.29 + 1.0)
    return min(1.0, max(0.0, season + wobble))

print(f"place San_Francisco_synthetic\nlatitude {LAT:.2f}\nlongitude {LON:.2f}\ntime_zone {MER:.0f}\n"
      "site_elevation 5\nweather_data_file_units 1")
day = 0
for month, ndays in enumerate(DAYS, 1):
    for mday in range(1, ndays + 1):
        day += 1
        decl = math.radians(23.45) * math.sin(2 * math.pi * (284 + day) / 365)
        b = 2 * math.pi * (day - 81) / 364
        eot_h = (9.87 * math.sin(2 * b) - 7.53 * math.cos(b) - 1.5 * math.sin(b)) / 60
        c = cloudiness(day)
        for hour in range(24):
            t = hour + 0.5
            solar = t + eot_h + (MER - LON) / 15
            omega = math.radians(15 * (solar - 12))
            phi = math.radians(LAT)
            sin_alt = math.sin(phi) * math.sin(decl) + math.cos(phi) * math.cos(decl) * math.cos(omega)
            if sin_alt <= 0.01:
                dni = dhi = 0
            else:
                clear_dni = 1000 * math.exp(-0.14 / sin_alt)
                dni = round(clear_dni * (1 - c) ** 1.5)
                dhi = round(sin_alt * (60 + 300 * c * (1 - 0.4 * c)) + 20)
            print(f"{month} {mday} {t:.3f} {dni} {dhi}")
