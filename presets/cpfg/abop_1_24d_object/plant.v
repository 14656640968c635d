/* plant.v - the view file of the object: what cpfg takes from it for the turtle. */
angle factor: 18                /* 360 / 18 = 20 degrees, the book's delta */
initial line width: 0.008 shaded /* world units: a diameter of 8 mm, a radius of 4 mm */
line width increment: 0
initial color: 0
color increment: 1
/* Only cpfg's window: read and ignored by sylva. */
viewpoint: 0,0,1
view reference point: 0,0,0
twist: 0
projection: parallel
front distance: -1000
back distance: 1000
scale factor: 0.9
z buffer: on
