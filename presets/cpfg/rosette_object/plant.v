/* plant.v - the view file: angle, widths, the two sides' colours, the flower's triangles. */
angle factor: 16                  /* 22.5 degrees */
initial line width: 0.006 shaded  /* world units: a 6 mm stem */
initial color: 1 2                /* leaves dark green above (the front), pale beneath (the back) */
color increment: 1 1
tsurface: p petals.ray 0.05       /* the flower: petals.ray's triangles, 5 cm a unit */
/* Only cpfg's window: read and ignored by sylva. */
viewpoint: 0,1,1
view reference point: 0,0,0
projection: perspective
