# Rest start of the paper's case (the eccentric load as a step): the
# converged model against n = 20 and n = 50 with the static correction, and
# the converged response low-passed at the 20th rope mode (what a 20-mode
# model can represent).  Data: rest.csv from convergence.sh.
set terminal pngcairo size 1100,900 font ",10"
set output "rest_start.png"
set datafile separator ","
set key autotitle columnhead
set multiplot layout 3,1
set grid
set xlabel "t (s)"
set key top right font ",9"
set title "Rest start, tilt: converged (corrected n = 400, 0.625 ms) vs n = 20 / 50 (correction on); n = 20 off is 33 % low"
set ylabel "theta (mrad)"
set xrange [0:3]
plot "rest.csv" u 1:($2*1e3) w l lw 2 lc rgb "black" t "converged", \
     "" u 1:($10*1e3) w l lw 1.5 dt 2 lc rgb "gray50" t "converged, low-passed at f_{20} = 3.1 Hz", \
     "" u 1:($4*1e3) w l lw 1.5 lc rgb "red" t "n = 20, on", \
     "" u 1:($8*1e3) w l lw 1 lc rgb "blue" t "n = 50, on", \
     "" u 1:($6*1e3) w l lw 1 lc rgb "orange" t "n = 20, off"
set title "Rest start, top-rope sleeve force lambda_1: the 6-ms twist, the 16-m segment between the sleeves ringing (3.9 Hz, 7.8 Hz, ...), reflections"
set ylabel "lambda_1 (N)"
plot "rest.csv" u 1:3 w l lw 2 lc rgb "black" t "converged", \
     "" u 1:11 w l lw 1.5 dt 2 lc rgb "gray50" t "converged, low-passed at f_{20}", \
     "" u 1:5 w l lw 1.5 lc rgb "red" t "n = 20, on", \
     "" u 1:9 w l lw 1 lc rgb "blue" t "n = 50, on"
set title "lambda_1, 5-7 s: n = 20 follows the low-passed converged force; the content above f_{20} (3.2 % nRMS) is beyond any 20-mode rope"
set xrange [5:7]
plot "rest.csv" u 1:3 w l lw 2 lc rgb "black" t "converged", \
     "" u 1:11 w l lw 1.5 dt 2 lc rgb "gray50" t "converged, low-passed at f_{20}", \
     "" u 1:5 w l lw 1.5 lc rgb "red" t "n = 20, on", \
     "" u 1:9 w l lw 1 lc rgb "blue" t "n = 50, on"
unset multiplot
