import sys, collections
rows=[l.rstrip('\n').split('|') for l in open(sys.argv[1]) if l.strip()]
seen=[];order=[];climbs=[];prev=None
runs=[]  # room runs
for i,(d,f,r,rv) in enumerate(rows,1):
    if r!=prev:
        if r in seen: climbs.append((i,prev,r,f))
        else: seen.append(r)
        runs.append(r)
    prev=r
print("stops",len(rows),"first-visit stops",sum(1 for x in rows if x[3]!='rv'),"rooms",len(seen),"climbs",len(climbs),"room runs",len(runs))
pair=collections.Counter(); rt=collections.Counter()
for (i,a,b,f) in climbs: pair[tuple(sorted((a,b)))]+=1
for k in range(2,len(runs)):
    if runs[k]==runs[k-2]: rt[tuple(sorted((runs[k],runs[k-1])))]+=1
print("climbs by pair:",pair.most_common(8))
print("A->B->A returns by pair:",rt.most_common(8))
for c in climbs: print(" climb at stop",c[0],c[1],"->",c[2],"(",c[3],")")
print("rooms in order:")
for n,r in enumerate(seen,1): print(n,r)
