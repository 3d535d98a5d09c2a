import sys
def climbs(rows):
    seen=set();prev=None;n=0
    for d,f,r,rv in rows:
        if r!=prev:
            if r in seen: n+=1
            else: seen.add(r)
        prev=r
    return n,len(seen)
rows=[l.rstrip('\n').split('|') for l in open(sys.argv[1]) if l.strip()]
base=climbs(rows)
print("base climbs,rooms",base)
moves={
 "a check_template_size->study/data_scope":{"check_template_size":"study/data_scope"},
 "b reference_q_measure,compression_tests->study/data_scope":{"reference_q_measure":"study/data_scope","compression_tests":"study/data_scope"},
 "a+b":{"check_template_size":"study/data_scope","reference_q_measure":"study/data_scope","compression_tests":"study/data_scope"},
 "c by_material,stored_cell,sheared_for->calibration_session":{"by_material":"study/calibration_session","stored_cell":"study/calibration_session","sheared_for":"study/calibration_session"},
 "c2 by_material->calibration_jobs":{"by_material":"study/calibration_jobs"},
 "d Misfit::values->misfit_curve_noise":{"Misfit::values":"fit/misfit_curve_noise"},
 "d2 values+build_summary_noise+quantities->mcn":{"Misfit::values":"fit/misfit_curve_noise","Misfit::build_summary_noise":"fit/misfit_curve_noise"},
 "d3 build_curve_noise..all curve-noise->misfit":{f:"fit/misfit" for f in ["Misfit::build_curve_noise","replicate_scatter","key_of","pooled_scale","ensemble_scatter","fitted_length","data_noise","Misfit::add_test_covariance","for_each_pair","Misfit::add_cell_bias","Misfit::add_correlated"]},
 "f Session::state_text->diagnosis_report":{"Session::state_text":"study/diagnosis_report"},
 "i heldout_parts->fit/diagnose":{"heldout_parts":"fit/diagnose"},
 "i2 heldout_chi2->fit/heldout_parts":{"heldout_chi2":"fit/heldout_parts","heldout_parts":"fit/heldout_parts"},
 "k check_plausible->data/measured":{"check_plausible":"data/measured"},
 "l generic_rival->fit/verdict":{"generic_rival":"fit/verdict"},
 "m quantity_group,feature_unit->calibration_report":{"quantity_group":"fit/calibration_report","feature_unit":"fit/calibration_report"},
 "n matched-> (none)":{},
}
for name,m in moves.items():
    r2=[[d,f,m.get(f,r),rv] for d,f,r,rv in rows]
    c=climbs(r2); print(f"{name}: climbs {c[0]} ({c[0]-base[0]:+d}), rooms {c[1]}")
more={
 "o noise_table,gain_tables->diagnosis_report":{"noise_table":"study/diagnosis_report","gain_tables":"study/diagnosis_report"},
 "o+f":{"noise_table":"study/diagnosis_report","gain_tables":"study/diagnosis_report","Session::state_text":"study/diagnosis_report"},
 "p write_measured_curves->calibration_report":{"write_measured_curves":"fit/calibration_report"},
 "q errors_csv,error_rows->calibration_session":{"errors_csv":"study/calibration_session","error_rows":"study/calibration_session"},
 "r predictions_of->calibration_session? (no)":{},
 "made (the diagnosis's tables and state line to its report)":{"noise_table":"study/diagnosis_report","gain_tables":"study/diagnosis_report","Session::state_text":"study/diagnosis_report"},
}
allm={}
moves.update(more)
for k in ["a+b","c by_material,stored_cell,sheared_for->calibration_session","d3 build_curve_noise..all curve-noise->misfit","o+f","l generic_rival->fit/verdict","i heldout_parts->fit/diagnose"]:
    allm.update(moves[k])
more["ALL(a+b,c,d3,o+f,l,i)"]=allm
for name,m in more.items():
    r2=[[d,f,m.get(f,r),rv] for d,f,r,rv in rows]
    c=climbs(r2); print(f"{name}: climbs {c[0]} ({c[0]-base[0]:+d}), rooms {c[1]}")
