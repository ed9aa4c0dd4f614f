# One-off generator of trapezoid.msh (Gmsh 4.1 ASCII via meshio): python trapezoid_gen.py
# one-off generator of trapezoid.msh (Gmsh 4.1 ASCII, written with meshio)
import numpy as np
import meshio
from scipy.spatial import Delaunay
rng = np.random.default_rng(6)
c = np.array([[0,0],[4,0],[4,2],[0,3]], float)
def side(a,b,n):
    s=np.linspace(0,1,n+1)[:-1]
    return a+(b-a)*s[:,None]
bnd = np.vstack([side(c[0],c[1],10), side(c[1],c[2],5), side(c[2],c[3],10), side(c[3],c[0],7)])
X,Y = np.meshgrid(np.linspace(0.3,3.7,9), np.linspace(0.3,2.7,7))
P = np.stack([X.ravel(),Y.ravel()],1) + rng.uniform(-0.08,0.08,(X.size,2))
P = P[P[:,1] < 3 - 0.25*P[:,0] - 0.2]
pts = np.vstack([bnd,P])
tri = Delaunay(pts).simplices.astype(np.int64)
a = pts[tri]
d1=a[:,1]-a[:,0]
d2=a[:,2]-a[:,0]
ar = d1[:,0]*d2[:,1]-d1[:,1]*d2[:,0]
tri[ar<0] = tri[ar<0][:,[0,2,1]]
print("min area", abs(ar).min())
nb = len(bnd)
idx = np.arange(nb)
segs = np.stack([idx, (idx+1)%nb],1)
names = ["floor"]*10 + ["clamp"]*5 + ["top"]*10 + ["load"]*7
tags = {"floor":1,"clamp":2,"top":3,"load":4}
lt = np.array([tags[n] for n in names])
pts3 = np.hstack([pts, np.zeros((len(pts),1))])
dt = np.zeros((len(pts),2),int)
dt[:]= [2,10]
dt[:nb,0]=1
dt[:nb,1]=lt
blocks = [("line", segs[lt == k]) for k in (1, 2, 3, 4)] + [("triangle", tri)]
phys = [np.full(int((lt == k).sum()), k) for k in (1, 2, 3, 4)] + [np.full(len(tri), 10)]
m = meshio.Mesh(pts3, blocks, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
    point_data={"gmsh:dim_tags": dt},
    field_data={"floor":np.array([1,1]),"clamp":np.array([2,1]),"top":np.array([3,1]),"load":np.array([4,1]),"body":np.array([10,2])})
meshio.write("trapezoid.msh", m, file_format="gmsh", binary=False)
print(len(pts), len(tri))
