# Plot of a `lash hil run` (its master.csv): reference and measured pressure [kPa] and the
# valve current [mA] against time. Usage: gnuplot -e "dir='hil-out'" scripts/plot_hil_run.gp
# writes dir/hil_run.png.
set datafile separator ','
set terminal pngcairo size 1000,700
set output dir.'/hil_run.png'
set multiplot layout 2,1 title 'lash hil run: master (default controller: PI + deadzone inverse from lash identification)'
set ylabel 'pressure [kPa]'
set grid
plot dir.'/master.csv' using (column('t_s')):(column('reference_kPa')) with lines title 'reference', \
     '' using (column('t_s')):(column('measured_kPa')) with lines title 'measured'
set ylabel 'current [mA]'
set xlabel 't [s]'
plot dir.'/master.csv' using (column('t_s')):(column('current_mA')) with lines title 'current'
unset multiplot
