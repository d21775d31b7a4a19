within RoverTerramechanics.Functions;
function gaussLegendre "Node i of the n-point Gauss-Legendre rule on [0, 1] and its weight"
  input Integer n "Number of nodes";
  input Integer i "Node, 1..n (nodes in increasing order)";
  output Real u "Node in [0, 1]";
  output Real w "Weight (the n weights sum to 1)";
protected
  Real x "Node on [-1, 1], a root of the Legendre polynomial P_n";
  Real p0 "P_(m-2)(x), then P_(n-1)(x)";
  Real p1 "P_(m-1)(x), then P_n(x)";
  Real p2;
  Real dp "P_n'(x)";
algorithm
  // Tricomi's estimate of the i-th largest root, then Newton on P_n (quadratic convergence:
  // 10 steps are far more than double precision needs).
  x := cos(3.141592653589793*(n + 1 - i - 0.25)/(n + 0.5));
  dp := 1;
  p0 := 1;
  p1 := x;
  p2 := x;
  for k in 1:10 loop
    p0 := 1;
    p1 := x;
    for m in 2:n loop
      p2 := ((2*m - 1)*x*p1 - (m - 1)*p0)/m;
      p0 := p1;
      p1 := p2;
    end for;
    dp := n*(x*p1 - p0)/(x*x - 1);
    x := x - p1/dp;
  end for;
  u := (1 + x)/2;
  w := 1/((1 - x*x)*dp*dp);
  annotation (Documentation(info="<html>
<p>The n-point Gauss-Legendre rule integrates polynomials of degree 2n - 1 exactly:
&int;<sub>0</sub><sup>1</sup> f(u) du &asymp; &sum; w<sub>i</sub> f(u<sub>i</sub>), with
u<sub>i</sub> = (1 + x<sub>i</sub>)/2 for the roots x<sub>i</sub> of the Legendre polynomial
P<sub>n</sub> and w<sub>i</sub> = 1/((1 - x<sub>i</sub><sup>2</sup>) P<sub>n</sub>'(x<sub>i</sub>)<sup>2</sup>)
(half the weight on [-1, 1]). The roots are found by Newton's method from Tricomi's estimate
cos(&pi;(k - 1/4)/(n + 1/2)) of the k-th largest root. Called with constant arguments (as by
<code>contactForces</code>), a tool evaluates it once when it translates the model.</p>
</html>"));
end gaussLegendre;
