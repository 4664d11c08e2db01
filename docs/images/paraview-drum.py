# A drum run's snapshots in ParaView, rendered without a display (docs/images/drying-drum-paraview.png):
#   xvfb-run -a pvpython docs/images/paraview-drum.py <snapshots dir> <output png>
# (Debian: apt-get install paraview python3-paraview xvfb; ParaView 5.11 there renders through X, hence xvfb-run.)
# The particles as spheres of their own radius coloured by temperature, the gas cells' temperature behind them,
# at the last time of the run, looking along the drum's axis.
import sys
from paraview.simple import *

snapshots, out = sys.argv[1], sys.argv[2]
particles = PVDReader(FileName=snapshots + "/particles.pvd")
gas = PVDReader(FileName=snapshots + "/gas.pvd")
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = particles.TimestepValues[-1]

view = CreateView("RenderView")
view.ViewSize = [1200, 900]
view.UseColorPaletteForBackground = 0
view.Background = [1.0, 1.0, 1.0]
view.OrientationAxesVisibility = 0

# The gas inside the drum (blocked cells hidden), as a backdrop.
inside = Threshold(Input=gas, Scalars=["CELLS", "blocked"], LowerThreshold=0, UpperThreshold=0)
gas_display = Show(inside, view)
ColorBy(gas_display, ("CELLS", "temperature_k"))
gas_lut = GetColorTransferFunction("temperature_k")
gas_lut.ApplyPreset("Cool to Warm", True)
gas_display.Opacity = 0.35

spheres = Show(particles, view)
spheres.SetRepresentationType("Point Gaussian")
spheres.ShaderPreset = "Sphere"
spheres.ScaleByArray = 1
spheres.SetScaleArray = ["POINTS", "radius_m"]
spheres.UseScaleFunction = 0
spheres.GaussianRadius = 1.0
ColorBy(spheres, ("POINTS", "temperature_k"))
lut = GetColorTransferFunction("temperature_k")
lut.ApplyPreset("Cool to Warm", True)
lut.RescaleTransferFunction(298.15, 373.15)
bar = GetScalarBar(lut, view)
bar.Title = "temperature [K]"
bar.ComponentTitle = ""
bar.TitleColor = [0.0, 0.0, 0.0]
bar.LabelColor = [0.0, 0.0, 0.0]
spheres.SetScalarBarVisibility(view, True)

version = GetParaViewVersion()
text = Text(Text="granflow snapshots: drying drum, t = %.1f s (ParaView %d.%d)" % (particles.TimestepValues[-1], version.major, version.minor))
text_display = Show(text, view)
text_display.Color = [0.0, 0.0, 0.0]
text_display.WindowLocation = "Upper Center"

view.CameraPosition = [0.0, 0.0, 0.5]
view.CameraFocalPoint = [0.0, 0.0, 0.0062]
view.CameraViewUp = [0.0, 1.0, 0.0]
view.CameraParallelProjection = 1
view.CameraParallelScale = 0.075
Render(view)
SaveScreenshot(out, view, ImageResolution=[1200, 900])
