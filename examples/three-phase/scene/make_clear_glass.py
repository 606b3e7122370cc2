#!/usr/bin/env python3
"""Writes clear_glass_kf.xml: a Klems full BSDF of a single clear pane (6 mm, n = 1.52, normal
visible transmittance 0.88), for the west window group of the example office.

A specular pane maps each incident Klems patch to the same patch index (straight-through
transmission and mirror reflection), so every matrix is diagonal:
    BTDF[i][i] = tau(theta_i) / lambda_i,   BRDF[i][i] = rho(theta_i) / lambda_i
with lambda_i = pi (cos^2 theta_lo - cos^2 theta_hi) / nphi (projected solid angle of patch i) and
tau, rho from Fresnel's equations for both polarisations, with multiple reflections and absorption
inside the pane, at the centre angle of the patch's ring. Usage: make_clear_glass.py > clear_glass_kf.xml
"""
import math

N = 1.52            # refractive index
A_NORMAL = 0.9582   # internal transmittance of one pass at normal incidence (gives tau(0) = 0.88)
BOUNDS = [0, 5, 15, 25, 35, 45, 55, 65, 75, 90]
NPHI = [1, 8, 16, 20, 24, 24, 24, 16, 12]


def pane(theta_deg):
    """Transmittance and reflectance of the pane for light arriving at theta (degrees)."""
    ci = math.cos(math.radians(theta_deg))
    si = math.sin(math.radians(theta_deg))
    st = si / N
    ct = math.sqrt(1 - st * st)
    rs = ((ci - N * ct) / (ci + N * ct)) ** 2
    rp = ((N * ci - ct) / (N * ci + ct)) ** 2
    a = A_NORMAL ** (1 / ct)
    tau = rho = 0.0
    for r in (rs, rp):
        tau += 0.5 * (1 - r) ** 2 * a / (1 - r * r * a * a)
        rho += 0.5 * (r + (1 - r) ** 2 * r * a * a / (1 - r * r * a * a))
    return tau, rho


def patches():
    """(centre theta, lambda) of each of the 145 patches in Klems order."""
    out = []
    for k in range(len(NPHI)):
        lo, hi = math.radians(BOUNDS[k]), math.radians(BOUNDS[k + 1])
        lam = math.pi * (math.cos(lo) ** 2 - math.cos(hi) ** 2) / NPHI[k]
        centre = 0.0 if k == 0 else 0.5 * (BOUNDS[k] + BOUNDS[k + 1])
        out += [(centre, lam)] * NPHI[k]
    return out


def block(direction, kind, values):
    n = len(values)
    rows = []
    for i in range(n):
        row = ["0"] * n
        row[i] = "%.6e" % values[i]
        rows.append(" ".join(row) + ",")
    return f"""		<WavelengthDataBlock>
			<WavelengthDataDirection>{direction}</WavelengthDataDirection>
			<ColumnAngleBasis>LBNL/Klems Full</ColumnAngleBasis>
			<RowAngleBasis>LBNL/Klems Full</RowAngleBasis>
			<ScatteringDataType>{kind}</ScatteringDataType>
			<ScatteringData>
{chr(10).join(rows)}
			</ScatteringData>
		</WavelengthDataBlock>
"""


def main():
    ps = patches()
    t = [pane(th)[0] / lam for th, lam in ps]
    r = [pane(th)[1] / lam for th, lam in ps]
    basis = ""
    for k in range(len(NPHI)):
        centre = 0 if k == 0 else 0.5 * (BOUNDS[k] + BOUNDS[k + 1])
        basis += f"""			<AngleBasisBlock>
				<Theta>{centre:g}</Theta>
				<nPhis>{NPHI[k]}</nPhis>
				<ThetaBounds>
					<LowerTheta>{BOUNDS[k]}</LowerTheta>
					<UpperTheta>{BOUNDS[k + 1]}</UpperTheta>
				</ThetaBounds>
			</AngleBasisBlock>
"""
    data = ""
    for direction, kind, v in (("Transmission Front", "BTDF", t), ("Transmission Back", "BTDF", t),
                               ("Reflection Front", "BRDF", r), ("Reflection Back", "BRDF", r)):
        data += f"""	<WavelengthData>
		<LayerNumber>System</LayerNumber>
		<Wavelength unit="Integral">Visible</Wavelength>
		<SourceSpectrum>CIE Illuminant D65 1nm.ssp</SourceSpectrum>
		<DetectorSpectrum>ASTM E308 1931 Y.dsp</DetectorSpectrum>
{block(direction, kind, v)}	</WavelengthData>
"""
    print(f"""<?xml version="1.0" encoding="UTF-8"?>
<!-- Created by: make_clear_glass.py (fenestra example): clear pane, n = {N}, tau(0) = {pane(0)[0]:.4f} -->
<WindowElement xmlns="http://windows.lbl.gov" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
<WindowElementType>System</WindowElementType>
<FileType>BSDF</FileType>
<Optical>
<Layer>
	<Material>
		<Name>Clear 6 mm</Name>
		<Manufacturer>fenestra example</Manufacturer>
		<DeviceType>Other</DeviceType>
		<Thickness unit="meter">0</Thickness>
		<Width unit="meter">1</Width>
		<Height unit="meter">1</Height>
	</Material>
	<DataDefinition>
		<IncidentDataStructure>Columns</IncidentDataStructure>
		<AngleBasis>
			<AngleBasisName>LBNL/Klems Full</AngleBasisName>
{basis}		</AngleBasis>
	</DataDefinition>
{data}</Layer>
</Optical>
</WindowElement>""")


if __name__ == "__main__":
    main()
