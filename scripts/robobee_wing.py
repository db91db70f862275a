import numpy as np, mujoco, time
from mjeap.system import attach, System
T_EFF = 4000.0          # rad/m, seed 003 sec. 6.1
SPAN, CHORD, THICK, WMASS = 15.0, 4.0, 0.02, 0.5   # mm, mm, mm, mg (assumed, to be cited)
spec = mujoco.MjSpec.from_string(f'''<mujoco>
<option gravity="0 0 -9.80665e-3" density="1.2e-3" viscosity="1.8e-5"/>
<worldbody>
  <site name="mount" pos="0 0 0"/>
  <body name="wing" pos="-5 0 0">
    <joint name="stroke" type="hinge" axis="0 0 1"/>
    <geom name="wing" type="box" size="{SPAN/2} {THICK/2} {CHORD/2}" pos="{-SPAN/2 - 1} 0 0" mass="{WMASS}"
          fluidshape="ellipsoid" contype="0" conaffinity="0" rgba="0.8 0.8 1 0.5"/>
  </body>
</worldbody></mujoco>''')
act = attach(spec, "robobee" if False else "pzt-robobee", site="mount", prefix="act", contact=False)
lay = act.twin.layout; u = act.twin.units
tip = spec.add_tendon(name="tip_deflection")
for j, x in zip(act.joints, lay.hinge_x):
    tip.wrap_joint(j, (lay.tip_x - x) / u.length)
st = spec.add_tendon(name="stroke_angle"); st.wrap_joint("stroke", 1.0)
eq = spec.add_equality(type=mujoco.mjtEq.mjEQ_TENDON, name1="stroke_angle", name2="tip_deflection")
eq.data[:5] = [0, T_EFF * u.length, 0, 0, 0]
S = System(spec, [act])
m = S.model
print("dt", S.timestep, "wing I about hinge (mg mm2)", m.body_inertia[m.body('wing').id], m.body_mass[m.body('wing').id])
stroke = m.joint("stroke").qposadr[0]
for V in (100.0, 200.0):
    amps=[]
    for f in (30, 60, 90, 120, 150, 180, 210, 240, 270):
        n = 12
        ang=[]; tt=[]
        def on(sy):
            ang.append(sy.data.qpos[stroke]); tt.append(sy.time)
        t0=time.time()
        S.rollout([f"sine:{V/2}V@{f}Hz,offset={V/2}V"], n / f, sample_interval=1/(f*40), on_sample=on)
        ang=np.array(ang); tt=np.array(tt); late = tt > (n-4)/f
        amps.append(np.degrees(0.5*np.ptp(ang[late])))
        print(V, f, round(amps[-1],2), round(time.time()-t0,1), flush=True)
