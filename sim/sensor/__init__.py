"""The simulated camera's sensor: what turns the rendered light into the frame a camera gives.

The renderer draws a perfectly exposed, sharp, noiseless picture. A real camera integrates
light over an exposure time (so what moves smears), turns photons into electrons with
shot noise, adds read noise, amplifies by a gain, digitises, applies a tone curve and may
compress, while its auto-exposure follows the light with a lag. `spec` holds the sensor's
figures and the named presets (`ideal`: the renderer's frames as they are), `exposure`
the auto-exposure, `readout` the image formation from light to 8-bit pixels, `photometry`
how many electrons the rendered light is worth. Plain numpy: the world (sim.world.shutter)
renders the exposure window and hands the light to the sensor.
"""
