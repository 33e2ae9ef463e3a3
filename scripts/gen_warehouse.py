#!/usr/bin/python3
"""Writes a warehouse for accuracy and speed checks on an occlusion-heavy scene nobody tuned to
(issue 20): five racks of four shelves with uprights and crates in a closed 16 x 6 x 22 hall,
lit by N lights: 65% in 30 lamp clusters under the ceiling, the rest anywhere in the hall
(between the racks, near surfaces), a fifth of them spot lights pointing down.

  /usr/bin/python3 scripts/gen_warehouse.py SEED N OUT.ray
"""
import random, sys
random.seed(int(sys.argv[1])); N=int(sys.argv[2])
o=[]
o.append('SBT-raytracer 1.0')
o.append('camera { position = (1.5, 3.2, -9.5); viewdir = (0.15, -0.25, 1); updir = (0,1,0); fov = 62; aspectratio = 1; }')
def box(c,s,mat,rot=0):
    o.append('translate(%g,%g,%g, rotate(0,1,0,%g, scale(%g,%g,%g, box { material = %s; })))'%(c[0],c[1],c[2],rot,s[0],s[1],s[2],mat))
o.append('material = { name = conc; diffuse = (0.5,0.5,0.48); }')
o.append('material = { name = rack; diffuse = (0.3,0.35,0.6); specular = (0.3,0.3,0.3); shininess = 25; }')
o.append('material = { name = crate; diffuse = (0.6,0.45,0.25); }')
o.append('material = { name = wall; diffuse = (0.7,0.7,0.65); }')
W,H,D=16.0,6.0,22.0
box((0,-0.05,0),(W,0.1,D),'conc'); box((0,H+0.05,0),(W,0.1,D),'wall')
box((-W/2-0.05,H/2,0),(0.1,H,D),'wall'); box((W/2+0.05,H/2,0),(0.1,H,D),'wall')
box((0,H/2,D/2+0.05),(W,H,0.1),'wall'); box((0,H/2,-D/2-0.05),(W,H,0.1),'wall')
# racks: rows along z, with shelves and uprights
for r in range(5):
    x=-6+r*3.0
    for sh in range(4):
        box((x,0.4+sh*1.2,1.5),(1.0,0.06,14),'rack')
    for k in range(8):
        box((x-0.48,2.2,-5.5+k*2),(0.06,4.4,0.06),'rack'); box((x+0.48,2.2,-5.5+k*2),(0.06,4.4,0.06),'rack')
    for k in range(10):
        if random.random()<0.7:
            sh=random.randrange(4); box((x+random.uniform(-0.2,0.2),0.43+sh*1.2+0.3,-5+k*1.4),(0.7,0.55,1.0),'crate',random.uniform(-0.3,0.3))
lights=[]
nl=int(N*0.65); lamps=30
for i in range(lamps):
    cx=random.uniform(-7,7); cz=random.uniform(-9,10); cy=H-0.3
    for j in range(nl//lamps):
        lights.append((cx+random.gauss(0,0.15),cy+random.gauss(0,0.05),cz+random.gauss(0,0.15)))
while len(lights)<N:
    lights.append((random.uniform(-7.8,7.8),random.uniform(0.2,H-0.2),random.uniform(-10.8,10.8)))
P=250.0/N
for (x,y,z) in lights:
    if random.random()<0.2:
        o.append('spot_light { position = (%.4f,%.4f,%.4f); direction = (%.3f,-1,%.3f); colour = (%g,%g,%g); exponent = 4; cutoff = 50; }'%(x,y,z,random.uniform(-.4,.4),random.uniform(-.4,.4),P,P*0.95,P*0.85))
    else:
        o.append('point_light { position = (%.4f,%.4f,%.4f); colour = (%g,%g,%g); }'%(x,y,z,P,P*0.97,P*0.9))
open(sys.argv[3],'w').write('\n'.join(o)+'\n')
