"""The benchmark's scene suite (scripts/bench.py): the rows of the seed's table (key, name,
scene file, VPL target, render flags, the seed's published figure), the sentences describing
the with/without-GI image pairs, and the light counts of the scaling sweep. Data only: add a
scene to the benchmark here."""

# The seed's published figures (docs/SEED.md).
SEED_EMITTER = "43 s → 7 s (6.1×); 11.8 → 1.5 lights/pixel"
SEED_EMITTER_LIGHTS = "11.8 → 1.5 lights/pixel"
SEED_CORNELL = "2 s / 2031 s / 95 s (21.4×); 8,638 → 273.6 VPLs/pixel"

# The table's rows. vpls: target number of VPLs (the path count is found by `info`);
# gi: the scene has VPLs (no-extra-lights column = --gi off); brute: 'auto' (full resolution
# when the estimate allows) or 'reference' (always extrapolated).
ROWS = [
    dict(key="green", name="Green light emitter", scene="scenes/green_light_emitter.ray", seed=SEED_EMITTER),
    # The seed's light count (12): its brute force evaluated 11.8 lights per pixel, so this is the
    # row where lights per shading point compare with the seed's 1.5 at equal light counts.
    dict(key="green12", name="Green light emitter, the seed's 12 lights", scene="scenes/green_light_emitter_seed.ray",
         seed=SEED_EMITTER_LIGHTS),
    dict(key="green_dense", name="Green light emitter, 25× density", scene="scenes/green_light_emitter_dense.ray"),
    dict(key="luminous", name="Luminous object", scene="scenes/luminous_object.ray"),
    dict(key="luminous_dense", name="Luminous object, 25× density", scene="scenes/luminous_object_dense.ray"),
    dict(key="cornell", name="Cornell box, object light + GI", scene="scenes/cornell_box.ray", gi=True,
         vpls=8638, seed=SEED_CORNELL),
    dict(key="cornell_100k", name="Cornell box, 100,000 VPLs", scene="scenes/cornell_box.ray", gi=True,
         vpls=100000, brute="reference", pair=False),
    dict(key="cornell_1m", name="Cornell box, 1,000,000 VPLs", scene="scenes/cornell_box.ray", gi=True,
         vpls=1000000, brute="reference", pair=False),
    dict(key="cornell_water", name="Cornell water", scene="scenes/cornell_water.ray", gi=True),
    dict(key="church", name="Church", scene="scenes/church.ray", gi=True),
    dict(key="roman_hall", name="Roman hall", scene="scenes/roman_hall.ray", gi=True),
    # Occlusion-heavy scenes (issue 20): most lights are hidden from most points.
    dict(key="rooms", name="Rooms", scene="scenes/rooms.ray", gi=True),
    dict(key="column_hall", name="Column hall", scene="scenes/column_hall.ray", gi=True),
    # Environment light (issue 24): thousands of directional lights from a sky model or a map.
    dict(key="courtyard_sunsky", name="Courtyard, sun and sky", scene="scenes/courtyard_sunsky.ray"),
    dict(key="garden_hdr", name="Garden, HDR map", scene="scenes/garden_hdr.ray"),
    # Caustics (issue 25): each scene without caustic lights (light through glass by the
    # kt-weighted shadow ray; mirrors cast plain shadows) and with them (extra: render flags).
    dict(key="ball_lens", name="Ball lens, no caustics", scene="scenes/ball_lens.ray", extra=["--caustics", "0"]),
    dict(key="ball_lens_caustics", name="Ball lens, caustics (1M paths)", scene="scenes/ball_lens.ray"),
    dict(key="mirror_ring", name="Mirror ring, no caustics", scene="scenes/mirror_ring.ray", extra=["--caustics", "0"]),
    dict(key="mirror_ring_caustics", name="Mirror ring, caustics (1M paths)", scene="scenes/mirror_ring.ray"),
    dict(key="cornell_water_caustics", name="Cornell water, caustics (100k paths)", scene="scenes/cornell_water.ray",
         gi=True, extra=["--caustics", "100000"]),
]

# One sentence per with/without-GI pair, written after looking at the images.
GI_DESCRIPTIONS = {
    "cornell": "Without GI the ceiling, the upper corners and every box face turned away from the panel are "
               "black; with one bounce the ceiling is lit, the red and green walls bleed onto the boxes' sides "
               "and the shadows on the floor soften.",
    "cornell_water": "Without GI the ceiling is black and the water a dark green layer over a shadowed floor; "
                     "with GI the ceiling and the box fronts light up, the tall box's side turns red from the "
                     "wall, and the floor seen through the water brightens.",
    "church": "Without GI only what a window or lamp sees directly is lit and the vault above the clerestory "
              "stays dark; with GI the coloured window light spreads over the vault, the columns and the floor "
              "as a soft violet fill.",
    "roman_hall": "Without GI the coffers, the walls above the cornice and the far end stay a dim brown under the "
                  "oculi and the lamps; with GI the vault, the walls and the floor brighten to a warm ochre, the "
                  "coffers' sides lit by light bounced from the floor.",
    "rooms": "Without GI the ceiling around the camera room's dim warm panel, the upper corners and the underside "
             "of the table are black, and the rooms beyond show only what their own coloured panels see; with GI "
             "the ceiling and walls fill in and the floor by the left doorway warms with red light bounced from "
             "the room beyond.",
    "column_hall": "Without GI the ceiling between the beams, the beams' sides and the columns' far sides are "
                   "near black and each lamp leaves sharp column shadows on the floor; with GI the ceiling and "
                   "beams light up warm from the floor and the columns' shadowed sides fill in.",
}

SCALING_N = [1000, 10000, 100000, 1000000]
