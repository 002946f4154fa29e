// SPDX-License-Identifier: MIT
// Droplets.cs - two water droplets collide head-on in zero gravity (the scene of samples/demo.c),
// driven from C# through the sph bindings. Prints a line every 10 frames.
//
//   mcs -target:library -out:Sph.dll ../Sph.Generated.cs ../Sph.cs
//   mcs -r:Sph.dll -out:Droplets.exe Droplets.cs
//   LD_LIBRARY_PATH=<dir of libsph.so> mono Droplets.exe [frames]
using System;
using Sph;

static class Droplets
{
    static int Main(string[] args)
    {
        int frames = args.Length > 0 ? int.Parse(args[0]) : 30;
        using (var context = new Context(Backend.Auto))
        {
            var def = WorldDef.Default();
            def.ParticleSpacing = 0.01f;  // water at 1 cm spacing
            def.Capacity = 40000;
            using (var world = context.CreateWorld(def))
            {
                var p = world.Params;
                p.Gravity = new Vec3(0, 0, 0);
                world.Params = p;
                uint n = world.FillSphere(new Vec3(-0.08f, 0, 0), 0.06f, new Vec3(1.5f, 0, 0));
                n += world.FillSphere(new Vec3(0.08f, 0.03f, 0), 0.06f, new Vec3(-1.5f, 0, 0));
                Console.WriteLine("sph " + Library.VersionString(Library.Version) + ", " + context.Backend +
                                  " backend: two droplets, " + n + " particles");

                var positions = new Vec3[n];  // reused every frame: one bulk copy, no per-particle calls
                for (int frame = 1; frame <= frames; ++frame)
                {
                    world.Step(1f / 60f);
                    if (frame % 10 != 0 && frame != frames) continue;
                    world.CopyAttribute(SphAttribute.Position, positions);
                    float extent = 0;
                    foreach (var x in positions) extent = Math.Max(extent, Math.Abs(x.Y));
                    Stats s = world.GetStats();
                    Console.WriteLine(string.Format("frame {0,3}  substeps {1,3}  max speed {2:F2} m/s  sheet half-height {3:F3} m  {4:F1} ms",
                                                    frame, s.Substeps, s.MaxSpeed, extent, s.StepMs));
                }
            }
        }
        return 0;
    }
}
